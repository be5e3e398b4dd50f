// The pipeline runner: builds the pipeline an INI file describes ([pipeline], [output], [source],
// the stage sections and the output sections, from the registries of libs/msgs) and runs it on the
// event stream. Registering the types (mbot::app::RegisterAll) is the program's job, before BuildPlan.
#pragma once

#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "mbot/common/config.hpp"
#include "mbot/msgs/outputs.hpp"
#include "mbot/msgs/source.hpp"
#include "mbot/msgs/stage.hpp"

namespace mbot::pipeline {

using msgs::EventResult;
using msgs::Stage;

struct PipelineOptions {
  std::vector<std::string> stages;   // section names, in order
  std::vector<std::string> outputs;  // section names: where every event of the run also goes
  uint64_t seed = 1;
  std::string progress = "auto";  // auto, bar, lines, off
  long long max_events = 0;       // 0: all
  long long skip_events = 0;      // the input's first events, read and dropped
  double playback_speed = 0.0;    // a recording paced to this many times real time (0: unpaced)
};

struct OutputFolder {
  std::string dir = "out";
};

// Everything parsed and validated from a Config, before anything is opened or run.
struct PipelinePlan {
  PipelineOptions pipeline;
  OutputFolder output;
  msgs::SourceOptions source;
  std::vector<std::pair<std::string, std::unique_ptr<Stage>>> stages;  // section name, stage
  struct PlannedOutput {
    std::string name;  // its section
    std::unique_ptr<msgs::Output> output;
    msgs::OutputOptions options;
  };
  std::vector<PlannedOutput> outputs;
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
  std::vector<std::pair<std::string, msgs::OutputCounts>> outputs;  // per output: sent, dropped, failed
};

// Opens the source and runs every event through the stages until the end of the input or until
// `stop` becomes true; then every stage's Finish writes its outputs.
RunSummary RunPlan(PipelinePlan& plan, const std::atomic<bool>& stop);

// True when the configuration's source is a robot's bus (lcm_live, lcm_relay, ros2_live): its work comes in
// bursts (a scan every 100 ms), so OpenMP's worker threads should sleep between them rather than
// spin — libgomp's default spin after each parallel region cost the live autonomy ~7 % of a core
// (BENCHMARKS.md, "Live path"). The wait policy is read once at load, from OMP_WAIT_POLICY; the
// app re-executes itself with OMP_WAIT_POLICY=PASSIVE when this is true and it is unset. It reads
// the configuration's [source] type only, so the app decides before building the plan (which opens
// the bus) and builds it once. The second start itself costs ~0.2 CPU-s (loading the libraries).
bool SourceIsABus(const config::Config& config);

}  // namespace mbot::pipeline
