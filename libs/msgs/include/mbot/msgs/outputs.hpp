// Several outputs at once, none of them the last stage: the pipeline offers every event of the run
// (what the source gave and what the stages emitted, in order) to each output. Each output has its
// own thread and a bounded queue per kind of event; a full queue drops that kind's oldest event (or
// waits, for an output that must not lose any: a recorder), and a per-kind rate limit in data time
// thins what a viewer does not need at full rate. Drops are counted and reported with the run.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "mbot/msgs/stage.hpp"

namespace mbot::msgs {

// The pipeline's keys of an output's section: which channels, how fast, how much may wait.
struct OutputOptions {
  std::set<std::string> channels;           // empty: every channel
  std::map<EventKind, double> max_rate_hz;  // kinds thinned to at most this rate (data time)
  size_t queue_per_kind = 64;               // events of one kind waiting for the output thread
  bool wait_when_full = false;              // else drop the kind's oldest
};

// Reads the pipeline's keys (channels, max_rate_hz, queue_per_kind, when_full); the type's own keys
// are its factory's. `max_rate_hz = map:1, particles:5` names kinds by KeyName.
OutputOptions ParseOutputOptions(config::Section& section, const OutputType& type);

struct OutputCounts {
  long long offered = 0;                   // events the output's filters let in
  long long sent = 0;                      // handed to the output
  long long rate_limited = 0;              // left out by max_rate_hz
  std::map<EventKind, long long> dropped;  // oldest events dropped from a full queue, by kind
  std::string error;                       // the output's first failure (it then gets nothing more)
  long long dropped_total() const;
  std::string ToString() const;  // "812 sent, 3 dropped (map 3), 40 rate-limited"
};

// One output on its own thread.
class OutputRunner {
 public:
  OutputRunner(std::string name, std::unique_ptr<Output> output, OutputOptions options);
  ~OutputRunner();
  OutputRunner(const OutputRunner&) = delete;
  OutputRunner& operator=(const OutputRunner&) = delete;

  // Opens the output (on this thread) and starts its thread.
  void Open(const RunContext& context);
  // Queues the event when the filters let it in. Never blocks, unless the output waits when full.
  void Offer(const Event& event);
  // Sends what is still queued, stops the thread, closes the output; returns what happened.
  OutputCounts Close(bool interrupted);
  const std::string& name() const { return name_; }

 private:
  void Run();
  void StopThread();  // closing: the queue is sent, then the thread ends

  std::string name_;
  std::unique_ptr<Output> output_;
  OutputOptions options_;
  std::map<EventKind, int64_t> last_sent_us_;  // rate limits, on the pipeline's thread

  std::mutex mutex_;
  std::condition_variable ready_, room_;
  struct Queued {
    uint64_t seq;
    Event event;
    int64_t offered_wall_us;
  };
  std::deque<Queued> queues_[kEventKindCount];
  uint64_t next_seq_ = 0;
  size_t queued_ = 0;
  bool closing_ = false;
  bool failed_ = false;
  OutputCounts counts_;
  std::thread thread_;
};

}  // namespace mbot::msgs
