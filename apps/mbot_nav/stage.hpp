// The pipeline's building block: a stage consumes the event stream and writes its outputs at the
// end. Stage types are registered by name; the INI names the stages and their options.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mbot/drivers/events.hpp"
#include "mbot/drivers/source.hpp"

namespace mbot::config {
class Section;
}

namespace mbot::app {

class Stage;

// How stages talk to what comes after them: an emitted event (a pose estimate, a map, a path, a
// velocity command) goes at once to every later stage of the pipeline, in order, and then to the
// sink (the simulator, live LCM) when the source is one. The same stages therefore run on a log
// (where nothing listens to the commands), in the simulator and on a robot.
class Bus {
 public:
  virtual ~Bus() = default;
  virtual void Emit(const Stage* from, const drivers::Event& event) = 0;
  // Ends the run after the current event; every stage's Finish then runs as at the end of the input.
  virtual void RequestStop(const std::string& reason) = 0;
};

// A competition event's headline result, as its referee reports it: what a caller running several
// pipelines (the competition) gathers into one table.
struct EventResult {
  std::string event, arena;  // "Speed Run", the arena's name
  uint64_t seed = 0;
  std::string result;  // the mission's final state, or "time limit"
  double time_s = 0, real_time_factor = 0;
  int points = 0, max_points = 0, collisions = 0;
};

struct RunContext {
  std::string output_dir;  // exists when stages start
  uint64_t seed = 0;       // the one seed all randomness derives from
  const drivers::Source* source = nullptr;
  std::string source_path;
  Bus* bus = nullptr;  // set by the pipeline; valid from Start to Finish
  // Set by a referee in Finish, returned in RunSummary::event_result. Valid in Finish.
  std::optional<EventResult>* event_result = nullptr;
  // Where emitted events end up after the later stages (the simulator, live LCM), or nullptr on a
  // recorded dataset; the bus already forwards to it, so stages read it only to know there is one.
  drivers::Sink* sink = nullptr;
};

class Stage {
 public:
  virtual ~Stage() = default;
  // Called once before the first event (open outputs here, not in the constructor).
  virtual void Start(const RunContext& /*context*/) {}
  virtual void OnEvent(const drivers::Event& event) = 0;
  // Called once at the end, also after Ctrl-C (interrupted = true): write what was computed.
  virtual void Finish(const RunContext& context, bool interrupted) = 0;
};

// A stage type: its factory parses the stage's section (strictly) and builds the stage without
// touching any file. Called with a describe-mode section it documents the keys (--list-stages).
struct StageType {
  std::string name;
  std::string doc;
  std::function<std::unique_ptr<Stage>(config::Section&)> create;
};

// All registered stage types, sorted by name.
const std::vector<StageType>& StageTypes();
const StageType* FindStageType(const std::string& name);

// Registers the source types other libraries bring (libs/sim: sim) beside libs/drivers' own.
// Idempotent; BuildPlan and --list-sources call it.
void RegisterSources();

}  // namespace mbot::app
