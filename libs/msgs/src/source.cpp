#include "mbot/msgs/source.hpp"

#include <algorithm>
#include <deque>
#include <filesystem>
#include <stdexcept>

#include "mbot/common/config.hpp"
#include "mbot/common/files.hpp"

namespace mbot::msgs {
namespace {

// source type `none`: nothing to read.
class NoSource : public Source {
 public:
  std::optional<Event> Next() override { return std::nullopt; }
  double Progress() const override { return 1.0; }
  std::string Format() const override { return "no input"; }
  bool events_expected() const override { return false; }
};

// A deque: registering a type never moves the ones before it (FindSourceType's pointers stay valid).
std::deque<SourceType>& Registry() {
  static std::deque<SourceType> types = [] {
    std::deque<SourceType> t;
    SourceType none{"none",  "no input: for stages that make their own output (maze_generator)", nullptr, 0,
                    nullptr, [](const SourceOptions&) { return std::make_unique<NoSource>(); }};
    none.path_kind = SourceType::Path::kUnchecked;
    t.push_back(std::move(none));
    return t;
  }();
  return types;
}

}  // namespace

void RegisterSourceType(SourceType type) {
  if (FindSourceType(type.name)) throw std::logic_error("source type '" + type.name + "' is registered twice");
  Registry().push_back(std::move(type));
}

const std::deque<SourceType>& SourceTypes() { return Registry(); }

const SourceType* FindSourceType(const std::string& name) {
  for (const SourceType& t : Registry()) {
    if (t.name == name) return &t;
  }
  return nullptr;
}

SourceOptions ParseSourceOptions(config::Section& s) {
  SourceOptions o;
  std::vector<std::string> names = {"auto"};
  for (const SourceType& t : SourceTypes()) names.push_back(t.name);
  o.type = s.GetChoice("type", o.type, names,
                       "input format; auto detects it from the path and the file's content (an .arena file is the "
                       "simulator's world); lcm_live: a robot on the LCM bus (mbot_nav --list-sources)");
  const SourceType* chosen = FindSourceType(o.type);
  if (s.describing()) {
    for (const SourceType& t : SourceTypes()) {
      if (!t.default_url.empty()) {
        s.GetString("url", t.default_url, "a bus's URL (" + t.name + "; ttl=0 keeps LCM traffic on this machine)");
        break;
      }
    }
  }
  if (chosen && !chosen->default_url.empty()) {
    o.path = s.GetString("url", chosen->default_url, "the bus's URL");
  } else if (o.type == "none") {
    if (!s.GetPath("path", "", "type = none: no input (a path here is an error: nothing would read it)").empty()) {
      s.Fail("path", "type = none reads no input; name the input's type (e.g. type = camera for images)");
    }
  } else {
    o.path = s.RequirePath("path",
                           "the dataset to read (LCM log, MRPT rawlog, CARMEN log, map file, botlab A* poses file or "
                           "folder, Moving AI .scen), or the simulator's world (.arena or a map)");
  }
  // A type's own keys exist only for that type (elsewhere they are unknown keys); describe mode
  // (--list-stages) documents every type's. With type = auto the type is detected now (from the
  // extension alone when the path does not exist; opening it then says what is wrong).
  if (s.describing()) {
    for (const SourceType& t : SourceTypes()) {
      if (t.parse) t.parse(s, &o);
    }
    o.extra.reset();
    return o;
  }
  std::string type = o.type;
  if (type == "auto" && std::filesystem::exists(o.path)) {
    type = DetectFormat(o.path);
  } else if (type == "auto") {  // a missing file: its extension still says whose keys these are
    for (const SourceType& t : SourceTypes()) {
      if (t.detect && t.detect_order == 0 && t.detect(o.path)) {
        type = t.name;
        break;
      }
    }
  }
  if (const SourceType* t = FindSourceType(type); t && t->parse) t->parse(s, &o);
  return o;
}

void ParseChannelRoles(config::Section& s, ChannelRoles* roles) {
  ChannelRoles& r = *roles;
  r.odometry = s.GetList("odometry_channels", r.odometry, "channels whose poses are the robot's odometry");
  r.ground_truth = s.GetList("ground_truth_channels", r.ground_truth, "channels carrying ground-truth poses");
  r.rezero_ground_truth =
      s.GetList("rezero_ground_truth_channels", r.rezero_ground_truth,
                "ground-truth channels re-zeroed to start at the origin (first pose subtracted, rotated by -theta0)");
  r.reference_pose =
      s.GetList("reference_pose_channels", r.reference_pose, "channels with another estimator's poses (staff SLAM)");
  r.pose_estimate = s.GetList("pose_estimate_channels", r.pose_estimate,
                              "channels whose poses are this stack's own estimate (from another process)");
  r.velocity_command =
      s.GetList("velocity_command_channels", r.velocity_command, "channels whose twist messages are velocity commands");
}

std::string DetectFormat(const std::string& path) {
  std::vector<const SourceType*> ordered;
  for (const SourceType& t : SourceTypes()) {
    if (t.detect) ordered.push_back(&t);
  }
  std::stable_sort(ordered.begin(), ordered.end(),
                   [](const SourceType* a, const SourceType* b) { return a->detect_order < b->detect_order; });
  bool checked_file = false;
  for (const SourceType* t : ordered) {
    if (t->detect_order >= 0 && !checked_file) {
      checked_file = true;
      if (std::filesystem::is_directory(path)) throw std::runtime_error(path + ": is a directory, not a dataset file");
      RequireReadableFile(path);  // "no such file", "permission denied", … rather than a guess at the format
    }
    if (t->detect(path)) return t->name;
  }
  throw std::runtime_error(
      path +
      ": unrecognised format (not an LCM log, ROS 2 bag, MRPT rawlog, CARMEN log, map or arena); set source.type");
}

std::unique_ptr<Source> OpenSource(const SourceOptions& options) {
  const std::string type = options.type == "auto" ? DetectFormat(options.path) : options.type;
  const SourceType* t = FindSourceType(type);
  if (!t) throw std::runtime_error("source type '" + type + "' is not known");
  // A file type's path must be a readable file (a folder would read as an empty one); folder types,
  // buses and devices check their own.
  if (t->path_kind == SourceType::Path::kFile && t->default_url.empty() && !options.path.empty()) {
    if (std::filesystem::is_directory(options.path)) {
      throw std::runtime_error(options.path + ": is a directory, not a " + type + " file");
    }
    RequireReadableFile(options.path);
  }
  return t->open(options);
}

}  // namespace mbot::msgs
