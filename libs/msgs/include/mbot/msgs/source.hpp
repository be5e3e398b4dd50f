// One interface for every dataset and live input: a time-ordered stream of Events. Live transports
// and replay share it, so every replay exercises production code. Source types are registered by
// name by the libraries that read them (libs/drivers the dataset files, libs/lcm the LCM logs and
// bus, libs/sim the simulator); [source] names one.
#pragma once

#include <any>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "mbot/msgs/events.hpp"
#include "mbot/msgs/sink.hpp"
#include "mbot/msgs/topics.hpp"

namespace mbot::config {
class Section;
}

namespace mbot::msgs {

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
  // Where the stack's outputs go when the input is a robot (the simulator, a live bus) — the source
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

// How channel names map to roles. Pose-typed messages (LCM's pose_xyt_t, odometry_t, pose2D_t
// share one layout) get their meaning from the channel they arrive on.
struct ChannelRoles {
  std::vector<std::string> odometry = {topics::kLegacyOdometry, topics::kOdometry};
  std::vector<std::string> ground_truth = {topics::kTruePose, topics::kGroundTruthPose};
  // Ground-truth channels re-zeroed as the botlab README says: subtract the first pose, rotate by -θ0.
  std::vector<std::string> rezero_ground_truth = {topics::kGroundTruthPose};
  std::vector<std::string> reference_pose = {topics::kSlamPose};
  // The stack's own estimate coming back over a transport (a referee or a simulated robot listening
  // to an autonomy process): none by default, since on a log SLAM_POSE is the staff's reference.
  std::vector<std::string> pose_estimate = {};
  std::vector<std::string> velocity_command = {topics::kVelocityCommand};
};

struct SourceOptions {
  std::string type = "auto";  // a registered source type (SourceTypes()), or auto
  std::string path;           // required; for sim, the world file; for a bus, its URL
  ChannelRoles roles;
  // Seed of the source's randomness, e.g. the simulator's noise ([pipeline] seed, copied here by
  // the pipeline; not a [source] key).
  uint64_t seed = 1;
  // The options of the chosen type's own keys (CarmenOptions, LiveSourceOptions, SimSourceOptions …),
  // filled by that type's `parse`; empty when it has none or was not parsed (ExtraOr gives defaults).
  std::any extra;
};

// The type's own options when `parse` filled them, else the defaults.
template <typename T>
T ExtraOr(const SourceOptions& options) {
  const T* o = std::any_cast<T>(&options.extra);
  return o ? *o : T{};
}

// A source type: what it reads, how its files are recognised (type = auto), its own keys of
// [source], and how it opens.
struct SourceType {
  // What `path` names: a readable file (checked before `open`), a file or a folder, or anything
  // the type checks itself (a device, a pipeline, nothing).
  enum class Path { kFile, kFileOrFolder, kUnchecked };
  using Detect = std::function<bool(const std::string& path)>;
  using Parse = std::function<void(config::Section& section, SourceOptions* options)>;
  using Open = std::function<std::unique_ptr<Source>(const SourceOptions& options)>;

  SourceType(std::string name_, std::string doc_, Detect detect_, int detect_order_, Parse parse_, Open open_,
             Path path_kind_ = Path::kFile, std::string default_url_ = "")
      : name(std::move(name_)),
        doc(std::move(doc_)),
        detect(std::move(detect_)),
        detect_order(detect_order_),
        parse(std::move(parse_)),
        open(std::move(open_)),
        path_kind(path_kind_),
        default_url(std::move(default_url_)) {}

  std::string name;  // the [source] type value
  std::string doc;
  // True when `path` is this type's input (type = auto). Types are asked in order of
  // `detect_order` (extension checks before content sniffing), then of registration. May be empty.
  Detect detect;
  int detect_order = 0;
  // Reads the type's own keys of [source] into `options` (documents them in describe mode). May be
  // empty when the type has none beyond the common ones.
  Parse parse;
  // Opens the input. Throws std::runtime_error naming the path when it cannot be read.
  Open open;
  Path path_kind = Path::kFile;
  // A bus: the type reads [source] url (with this default) instead of path.
  std::string default_url;
};

// Adds a type; a second type of the same name is an error (std::logic_error).
void RegisterSourceType(SourceType type);
// Every registered type in registration order (pointers to them stay valid when more are registered).
const std::deque<SourceType>& SourceTypes();
// nullptr when no type has that name.
const SourceType* FindSourceType(const std::string& name);

// Reads [source]: the common keys, then the chosen type's own (with type = auto, the type detected
// from the path when it exists). Throws config::ConfigError naming the key on bad values.
SourceOptions ParseSourceOptions(config::Section& section);

// The channel-role keys of [source] (odometry_channels, ground_truth_channels, …), for the types
// whose messages take their meaning from the channel (LCM logs and the live bus).
void ParseChannelRoles(config::Section& section, ChannelRoles* roles);

// Opens the input named by the options, detecting the format from its content when type = auto.
// A source that is also the robot (the simulator, a live bus) takes the stack's outputs: Source::sink().
// Throws std::runtime_error naming the path when it cannot be read or recognised.
std::unique_ptr<Source> OpenSource(const SourceOptions& options);

// The type OpenSource would pick for `path` (the first registered type whose `detect` accepts it).
// Throws std::runtime_error naming the path when there is no such file or no type recognises it.
std::string DetectFormat(const std::string& path);

}  // namespace mbot::msgs
