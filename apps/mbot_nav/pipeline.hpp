// Builds the pipeline an INI file describes and runs it on the event stream.
#pragma once

#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "mbot/common/config.hpp"
#include "mbot/drivers/source_options.hpp"
#include "stage.hpp"

namespace mbot::app {

struct PipelineOptions {
  std::vector<std::string> stages;  // section names, in order
  uint64_t seed = 1;
  std::string progress = "auto";  // auto, bar, lines, off
  long long max_events = 0;       // 0: all
};

struct OutputOptions {
  std::string dir = "out";
};

// Everything parsed and validated from a Config, before anything is opened or run.
struct PipelinePlan {
  PipelineOptions pipeline;
  OutputOptions output;
  drivers::SourceOptions source;
  std::vector<std::pair<std::string, std::unique_ptr<Stage>>> stages;  // section name, stage
};

// Parses [pipeline], [output], [source] and every stage section strictly: unknown sections, unknown
// keys, missing required keys and bad values throw config::ConfigError naming file, section, key.
PipelinePlan BuildPlan(const config::Config& config);

struct RunSummary {
  long long events = 0;
  double data_seconds = 0.0;
  double wall_seconds = 0.0;
  bool interrupted = false;
  std::string stopped_by;                   // the reason a stage gave when it ended the run, else ""
  std::optional<EventResult> event_result;  // what a referee reported (RunContext::event_result)
};

// Opens the source and runs every event through the stages until the end of the input or until
// `stop` becomes true; then every stage's Finish writes its outputs.
RunSummary RunPlan(PipelinePlan& plan, const std::atomic<bool>& stop);

}  // namespace mbot::app
