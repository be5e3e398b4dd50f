// One interface for every dataset and live input: a time-ordered stream of Events. Live LCM and
// replay share it, so every replay exercises production code.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "mbot/drivers/events.hpp"
#include "mbot/drivers/sink.hpp"

namespace mbot::drivers {

// What a source learnt about one channel (or sensor label) of its input.
struct ChannelInfo {
  std::string type;        // message / observation type, e.g. "lidar_t", "CObservation2DRangeScan"
  std::string generation;  // message generation(s), e.g. "legacy 2017-2022", or "" when n/a
  EventKind kind = EventKind::kOther;
  bool decoded = true;  // false when the type is unknown and the messages are skipped
};

// Problems met while reading; each was also logged with its location.
struct SourceDiagnostics {
  int64_t resyncs = 0;            // times the reader lost sync and searched for the next record
  int64_t skipped_bytes = 0;      // bytes skipped while resynchronising
  int64_t rejected_messages = 0;  // malformed messages (bad lengths, counts, values)
  int64_t unknown_messages = 0;   // messages of an unknown type
  int64_t out_of_order = 0;       // events later than the reorder window allowed
  bool truncated_tail = false;    // the input ended in the middle of a record
};

class Source {
 public:
  virtual ~Source() = default;
  // The next event in time order, or nullopt at the end of the input.
  virtual std::optional<Event> Next() = 0;
  // Fraction of the input consumed, in [0, 1].
  virtual double Progress() const = 0;
  // A short human name of the input format ("LCM log", "MRPT rawlog (observations only)" …).
  virtual std::string Format() const = 0;
  // Where the stack's outputs go when the input is a robot (the simulator, live LCM) — the source
  // itself — or nullptr for a recorded dataset.
  virtual Sink* sink() { return nullptr; }
  // False for inputs that are no event stream (type none, a sweep folder): a run of no event is
  // then not a failed run.
  virtual bool events_expected() const { return true; }
  // Format-specific facts for summaries, e.g. {"sensory frames", "37"}.
  virtual std::vector<std::pair<std::string, std::string>> Details() const { return {}; }
  const std::map<std::string, ChannelInfo>& channels() const { return channels_; }
  const SourceDiagnostics& diagnostics() const { return diagnostics_; }

 protected:
  std::map<std::string, ChannelInfo> channels_;
  SourceDiagnostics diagnostics_;
};

}  // namespace mbot::drivers
