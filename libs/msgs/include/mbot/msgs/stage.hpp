// The pipeline's contract: a stage consumes the event stream and writes its outputs at the end; an
// output sends the run's events somewhere (a bus, a viewer, a file). Both are registered by type name
// from the library or file that owns the behaviour; the INI names the sections and their options.
#pragma once

#include <cstdint>
#include <atomic>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "mbot/msgs/events.hpp"
#include "mbot/msgs/sink.hpp"
#include "mbot/msgs/source.hpp"

namespace mbot::config {
class Section;
}

namespace mbot::msgs {

class Stage;

// How stages talk to what comes after them: an emitted event (a pose estimate, a map, a path, a
// velocity command) goes at once to every later stage of the pipeline, in order, then to the
// source's sink (the simulator, a live bus) when it has one, and to every output. The same stages
// therefore run on a log (where nothing listens to the commands), in the simulator and on a robot.
class Bus {
 public:
  virtual ~Bus() = default;
  virtual void Emit(const Stage* from, const Event& event) = 0;
  // Ends the run after the current event; every stage's Finish then runs as at the end of the input.
  virtual void RequestStop(const std::string& reason) = 0;
  // True when the run has outputs (a viewer, a recorder, a transport): a stage may skip work whose
  // events only an output would read (the referee's score so far).
  virtual bool Watched() const { return false; }
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

// Events from outside the run's source — a person's goal or teleop from a viewer — posted from any
// thread; the pipeline takes them in between the source's events, in the order they came, stamped
// with the data's time, and hands them to the stages and outputs like the source's own. Bounded:
// past `capacity` the oldest waiting is dropped (and counted).
class Inbox {
 public:
  explicit Inbox(size_t capacity = 256) : capacity_(capacity) {}
  void Post(Event event);
  std::vector<Event> Take();
  long long dropped() const;

 private:
  size_t capacity_;
  mutable std::mutex mutex_;
  std::deque<Event> events_;
  long long dropped_ = 0;
};

// How fast a recording plays: the pipeline paces a recorded source (one with no sink: a log, not
// the simulator or a robot) by its data clock — speed 0 as fast as it can, 1 real time, 4 four times
// — and holds it while paused. Set from any thread (a viewer's client); the pacer sees a change
// within 50 ms.
class Playback {
 public:
  explicit Playback(double speed = 0.0) : speed_(speed) {}
  void Set(double speed, bool paused) {
    speed_.store(speed < 0 ? 0.0 : speed);
    paused_.store(paused);
    version_.fetch_add(1);
  }
  double speed() const { return speed_.load(); }
  bool paused() const { return paused_.load(); }
  uint64_t version() const { return version_.load(); }

 private:
  std::atomic<double> speed_;
  std::atomic<bool> paused_{false};
  std::atomic<uint64_t> version_{0};
};

struct RunContext {
  std::string output_dir;  // exists when stages start
  uint64_t seed = 0;       // the one seed all randomness derives from
  const Source* source = nullptr;
  std::string source_path;
  Bus* bus = nullptr;  // set by the pipeline; valid from Start to Finish
  // Set by a referee in Finish, returned in RunSummary::event_result. Valid in Finish.
  std::optional<EventResult>* event_result = nullptr;
  // The source's sink (the simulator, a live bus), or nullptr on a recorded dataset; the bus
  // already forwards to it, so stages read it only to know there is one.
  Sink* sink = nullptr;
  // Where outputs post what comes back from their peers (a viewer's goal and teleop).
  Inbox* inbox = nullptr;
  // A recording's pace and pause (nullptr when the source is live or the simulator).
  Playback* playback = nullptr;
};

class Stage {
 public:
  virtual ~Stage() = default;
  // Called once before the first event (open outputs here, not in the constructor).
  virtual void Start(const RunContext& /*context*/) {}
  virtual void OnEvent(const Event& event) = 0;
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

// Adds a type; a second type of the same name is an error (std::logic_error).
void RegisterStageType(StageType type);
// All registered stage types, sorted by name.
std::vector<const StageType*> StageTypes();
const StageType* FindStageType(const std::string& name);

// A stage file registers its type when the program starts:
//   const msgs::RegisterStage kRegistered{{"name", "doc", factory}};
struct RegisterStage {
  explicit RegisterStage(StageType type) { RegisterStageType(std::move(type)); }
};

// An output: where the run's events go besides the stages (a transport to a viewer or a robot, a
// recorder). It runs on its own thread, fed through a bounded queue (msgs/outputs.hpp).
class Output : public Sink {
 public:
  // Called once before the first event, on the pipeline's thread (open files and sockets here).
  virtual void Open(const RunContext& /*context*/) {}
  // Called once after the last event was sent, also after Ctrl-C (interrupted = true): flush, close,
  // say what was sent.
  virtual void Close(bool /*interrupted*/) {}
  // What the output thread calls for each event: Send, unless the output wants to know when the
  // pipeline offered it (system clock, µs since the epoch: a viewer measures how late it shows it).
  virtual void SendOffered(const Event& event, int64_t /*offered_wall_us*/) { Send(event); }
};

// An output type: its factory parses the output's own keys of its section (the queue and rate keys
// are the pipeline's) and builds it without opening anything.
struct OutputType {
  std::string name;
  std::string doc;
  std::function<std::unique_ptr<Output>(config::Section&)> create;
  // A full queue: drop the kind's oldest event (a viewer, a bus) or wait for room (a recorder, which
  // must not lose what it records; a file is not a hostile peer).
  bool wait_when_full = false;
  // The default of the section's max_rate_hz ("map:2, particles:5"): what a viewer needs.
  std::string default_max_rate_hz;
};

void RegisterOutputType(OutputType type);
std::vector<const OutputType*> OutputTypes();  // sorted by name
const OutputType* FindOutputType(const std::string& name);

}  // namespace mbot::msgs
