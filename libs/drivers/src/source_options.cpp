#include "mbot/drivers/source_options.hpp"

#include "mbot/common/files.hpp"

#include <zlib.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <algorithm>
#include <deque>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "camera_source.hpp"
#include "carmen_source.hpp"
#include "lcm_live_source.hpp"
#include "lcm_log_source.hpp"
#include "mbot/common/config.hpp"
#include "mbot/common/strings.hpp"
#include "mbot/drivers/lcm_log.hpp"
#include "mbot/drivers/map_io.hpp"
#include "motor_samples_source.hpp"
#include "planning_cases_source.hpp"
#include "rawlog_source.hpp"

namespace mbot::drivers {
namespace {

// A map file as a source: one kMap event at t = 0.
class MapSource : public Source {
 public:
  explicit MapSource(const std::string& path) {
    grid_ = std::make_shared<mapping::OccupancyGrid>(ReadAnyMap(path, &format_));
    channels_["map"] = ChannelInfo{format_, "", EventKind::kMap, true};
  }
  std::optional<Event> Next() override {
    if (done_) return std::nullopt;
    done_ = true;
    return Event{0, 0, "map", EventKind::kMap, std::shared_ptr<const mapping::OccupancyGrid>(grid_)};
  }
  double Progress() const override { return done_ ? 1.0 : 0.0; }
  std::string Format() const override { return format_; }

 private:
  std::shared_ptr<mapping::OccupancyGrid> grid_;
  std::string format_;
  bool done_ = false;
};

}  // namespace

LiveSourceOptions ParseLiveSourceOptions(config::Section& s) {
  const auto doc = [](const char* text) { return std::string("lcm_live: ") + text; };
  LiveSourceOptions o;
  o.channels = s.GetList("channels", o.channels, doc("channels to subscribe to"));
  o.duration_s = s.GetDouble("duration_s", o.duration_s, doc("the run ends after this long (0: never) [s]"), 0.0, 1e7);
  o.end_after_silence_s =
      s.GetDouble("end_after_silence_s", o.end_after_silence_s,
                  doc("the run ends when no message arrived for this long (0: never) [s]"), 0.0, 1e7);
  o.stale_sensor_s = s.GetDouble("stale_sensor_s", o.stale_sensor_s,
                                 doc("a watched channel silent this long stops the robot [s]"), 0.01, 1e4);
  o.watched = s.GetList("watched_channels", o.watched, doc("channels whose silence stops the robot"));
  o.command_channel = s.GetString("command_channel", o.command_channel, doc("velocity commands go out here"));
  o.report_every_s = s.GetDouble("report_every_s", o.report_every_s,
                                 doc("log the loop rate and latency this often (0: never) [s]"), 0.0, 1e6);
  return o;
}

// lcm_relay.cpp
void ParseRelayOptions(config::Section& s, SourceOptions* o);

void ParseCameraSourceOptions(config::Section& s, SourceOptions* out) {
  CameraSourceOptions& o = out->camera;
  auto doc = [](const char* text) { return std::string("type = camera: ") + text; };
  o.fps =
      s.GetDouble("camera_fps", o.fps, doc("replay: frames 1/fps apart; a device is asked for this rate"), 0.1, 1000.0);
  o.width =
      static_cast<int>(s.GetInt("camera_width", o.width, doc("a device is asked for this width [px]"), 16, 10000));
  o.height =
      static_cast<int>(s.GetInt("camera_height", o.height, doc("a device is asked for this height [px]"), 16, 10000));
  o.timeout_s = s.GetDouble("camera_timeout_s", o.timeout_s,
                            doc("a live camera silent this long ends the stream, reported [s]"), 0.01, 3600.0);
  o.channel = s.GetString("camera_channel", o.channel, doc("the channel the frames are emitted on"));
}
std::unique_ptr<Source> OpenLcmRelay(const SourceOptions& options);

namespace {

bool IsCarmenText(const std::string& path) {
  // Text (possibly gzip-compressed): CARMEN logs start with comments or message names.
  gzFile f = gzopen(path.c_str(), "rb");
  if (!f) return false;
  char buf[256] = {0};
  const int n = gzread(f, buf, sizeof buf - 1);
  gzclose(f);
  if (n <= 0) return false;
  const std::string text(buf, n);
  for (const char* tag : {"#", "PARAM", "ODOM", "FLASER", "RLASER", "ROBOTLASER", "RAWLASER", "TRUEPOS", "SYNC"}) {
    if (text.rfind(tag, 0) == 0) return true;
  }
  return false;
}

bool IsLcmLog(const std::string& path) {
  unsigned char head[4] = {0, 0, 0, 0};
  std::ifstream in(path, std::ios::binary);
  in.read(reinterpret_cast<char*>(head), 4);
  const uint32_t word = (uint32_t(head[0]) << 24) | (uint32_t(head[1]) << 16) | (uint32_t(head[2]) << 8) | head[3];
  return in.gcount() == 4 && word == LcmLogReader::kSyncWord;
}

bool IsCases(const std::string& path, const char* type) {
  std::string cases;
  return IsPlanningCasesPath(path, &cases) && cases == type;
}

// source type `none`: nothing to read.
class NoSource : public Source {
 public:
  std::optional<Event> Next() override { return std::nullopt; }
  double Progress() const override { return 1.0; }
  std::string Format() const override { return "no input"; }
  bool events_expected() const override { return false; }
};

// libs/drivers' own types; detect_order < 0 may name a folder, the others need a regular file.
std::deque<SourceType> BuiltInTypes() {
  std::deque<SourceType> t;
  t.push_back({"astar_cases",
               "the botlab A* test cases: a folder of *_poses.txt files beside their maps, or one of them",
               [](const std::string& p) { return IsCases(p, "astar_cases"); }, -1, nullptr,
               [](const SourceOptions& o) { return std::make_unique<PlanningCasesSource>(o.path, "astar_cases"); }});
  t.push_back({"movingai", "a Moving AI .map.scen scenario file (its map beside it, or in ../../maps)",
               [](const std::string& p) { return IsCases(p, "movingai"); }, -1, nullptr,
               [](const SourceOptions& o) { return std::make_unique<PlanningCasesSource>(o.path, "movingai"); }});
  t.push_back({"map", "a map file (botlab .map, PGM + YAML, MRPT .gridmap/.simplemap, Moving AI .map): one map event",
               [](const std::string& p) { return IsMapFile(p); }, 0, nullptr,
               [](const SourceOptions& o) { return std::make_unique<MapSource>(o.path); }});
  t.push_back({"rawlog", "an MRPT rawlog (.rawlog, .rawlog.gz), both formats",
               [](const std::string& p) { return EndsWith(p, ".rawlog") || EndsWith(p, ".rawlog.gz"); }, 0, nullptr,
               [](const SourceOptions& o) { return std::make_unique<RawlogSource>(o); }});
  t.push_back({"motor_csv", "a motor calibration CSV (duty and wheel speed per channel)",
               [](const std::string& p) { return EndsWith(p, ".csv") && IsMotorSamplesFile(p); }, 0, nullptr,
               [](const SourceOptions& o) { return std::make_unique<MotorSamplesSource>(o.path); }});
  t.push_back({"lcm_log", "an LCM log (lcm-logger), every botlab message generation", IsLcmLog, 10, nullptr,
               [](const SourceOptions& o) { return std::make_unique<LcmLogSource>(o); }});
  t.push_back({"carmen", "a CARMEN log, plain or gzip", IsCarmenText, 20, nullptr,
               [](const SourceOptions& o) { return std::make_unique<CarmenSource>(o); }});
  t.push_back({"lcm_live", "a robot (or the simulated one) on the LCM bus, in wall-clock time; path is the LCM url",
               nullptr, 0, [](config::Section& s, SourceOptions* o) { o->live = ParseLiveSourceOptions(s); },
               [](const SourceOptions& o) { return std::make_unique<LcmLiveSource>(o); }});
  t.push_back({"camera",
               "camera frames: a device index, a video file or a GStreamer pipeline (OpenCV VideoCapture), or an "
               "image folder or file replayed at camera_fps",
               IsImageFileOrFolder, -1, ParseCameraSourceOptions,
               [](const SourceOptions& o) { return std::make_unique<CameraSource>(o); }});
  t.push_back({"none", "no input: for stages that make their own output (maze_generator)", nullptr, 0, nullptr,
               [](const SourceOptions&) { return std::make_unique<NoSource>(); }});
  t.push_back({"lcm_relay",
               "a fault-injecting relay between the robot's LCM group (url) and the autonomy's (relay_url): drops, "
               "delay, jitter, duplicates, reordering, corruption, silences",
               nullptr, 0, ParseRelayOptions, OpenLcmRelay});
  return t;
}

// A deque: registering a type never moves the ones before it (FindSourceType's pointers stay valid).
std::deque<SourceType>& Registry() {
  static std::deque<SourceType> types = BuiltInTypes();
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
  const bool live = o.type == "lcm_live" || o.type == "lcm_relay";
  if (live || s.describing()) {
    o.path = s.GetString("url", kDefaultLcmUrl,
                         "lcm_live: the LCM URL (ttl=0 keeps the traffic on this machine); lcm_relay: the robot's");
  }
  if (o.type == "none") {
    o.path = s.GetPath("path", "", "");
  } else if (!live) {
    o.path = s.RequirePath("path",
                           "the dataset to read (LCM log, MRPT rawlog, CARMEN log, map file, botlab A* poses file or "
                           "folder, Moving AI .scen), or the simulator's world (.arena or a map)");
  }
  auto& r = o.roles;
  r.odometry = s.GetList("odometry_channels", r.odometry, "LCM channels whose poses are the robot's odometry");
  r.ground_truth = s.GetList("ground_truth_channels", r.ground_truth, "LCM channels carrying ground-truth poses");
  r.rezero_ground_truth =
      s.GetList("rezero_ground_truth_channels", r.rezero_ground_truth,
                "ground-truth channels re-zeroed to start at the origin (first pose subtracted, rotated by -theta0)");
  r.reference_pose = s.GetList("reference_pose_channels", r.reference_pose,
                               "LCM channels with another estimator's poses (staff SLAM)");
  r.velocity_command = s.GetList("velocity_command_channels", r.velocity_command,
                                 "LCM channels whose twist2D_t messages are velocity commands");
  o.carmen_max_range_m =
      s.GetDouble("carmen_max_range_m", o.carmen_max_range_m,
                  "CARMEN FLASER range limit when the log's PARAM lines do not give one [m]", 0.1, 1000.0);
  o.carmen_file_order = s.GetChoice("carmen_order", "stamp", {"stamp", "file"},
                                    "CARMEN records in stamp order, or in file order with event times held "
                                    "non-decreasing (stamps that run backwards)") == "file";
  o.reorder_window_us = static_cast<int64_t>(
      1e6 * s.GetDouble("reorder_window_s", o.reorder_window_us * 1e-6,
                        "LCM log records are re-sorted by event time within this window [s]", 0.0, 10.0));
  // A type's own keys exist only for that type (elsewhere they are unknown keys); describe mode
  // (--list-stages) documents every type's. With type = auto the type is detected now (from the
  // extension alone when the path does not exist; opening it then says what is wrong).
  if (s.describing()) {
    for (const SourceType& t : SourceTypes()) {
      if (t.parse) t.parse(s, &o);
    }
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
      path + ": unrecognised format (not an LCM log, MRPT rawlog, CARMEN log, map or arena); set source.type");
}

std::unique_ptr<Source> OpenSource(const SourceOptions& options) {
  const std::string type = options.type == "auto" ? DetectFormat(options.path) : options.type;
  const SourceType* t = FindSourceType(type);
  if (!t) throw std::runtime_error("source type '" + type + "' is not known");
  // Only the A* cases and a sweep come as a folder; a folder anywhere else would read as an empty
  // file. A camera's path may be a device index or a pipeline: it checks its own.
  const bool bus = type == "lcm_live" || type == "lcm_relay" || type == "none" || type == "camera";
  const bool folder = type == "astar_cases" || type == "sweep";
  if (!folder && !bus && std::filesystem::is_directory(options.path)) {
    throw std::runtime_error(options.path + ": is a directory, not a " + type + " file");
  }
  if (!folder && !bus && !options.path.empty()) RequireReadableFile(options.path);
  return t->open(options);
}

const char* ToString(EventKind kind) {
  switch (kind) {
    case EventKind::kLidar: return "lidar";
    case EventKind::kOdometry: return "odometry";
    case EventKind::kEncoders: return "encoders";
    case EventKind::kImu: return "imu";
    case EventKind::kMotorCommand: return "motor command";
    case EventKind::kGroundTruth: return "ground truth";
    case EventKind::kReferencePose: return "reference pose";
    case EventKind::kMap: return "map";
    case EventKind::kPlanRequest: return "plan request";
    case EventKind::kWheelSpeed: return "wheel speed";
    case EventKind::kMotorSample: return "motor sample";
    case EventKind::kCollision: return "collision";
    case EventKind::kPoseEstimate: return "pose estimate";
    case EventKind::kPath: return "path";
    case EventKind::kSlamStatus: return "SLAM status";
    case EventKind::kMissionStatus: return "mission status";
    case EventKind::kParticles: return "particles";
    case EventKind::kTagSightings: return "tag sightings";
    case EventKind::kCameraFrame: return "camera frame";
    case EventKind::kForkliftCommand: return "forklift command";
    case EventKind::kForkliftStatus: return "forklift status";
    case EventKind::kCrates: return "crates";
    case EventKind::kOther: return "other";
  }
  return "?";
}

}  // namespace mbot::drivers
