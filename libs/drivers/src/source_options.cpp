#include "mbot/drivers/source_options.hpp"

#include <zlib.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "carmen_source.hpp"
#include "lcm_log_source.hpp"
#include "mbot/common/config.hpp"
#include "mbot/drivers/lcm_log.hpp"
#include "mbot/drivers/map_io.hpp"
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

SourceOptions ParseSourceOptions(config::Section& s) {
  SourceOptions o;
  o.type = s.GetChoice("type", o.type, {"auto", "lcm_log", "rawlog", "carmen", "map", "astar_cases", "movingai"},
                       "input format; auto detects it from the file's content");
  o.path = s.RequirePath("path", "the dataset to read (LCM log, MRPT rawlog, CARMEN log, map file, botlab A* poses file or folder, Moving AI .scen)");
  auto& r = o.roles;
  r.odometry = s.GetList("odometry_channels", r.odometry, "LCM channels whose poses are the robot's odometry");
  r.ground_truth = s.GetList("ground_truth_channels", r.ground_truth, "LCM channels carrying ground-truth poses");
  r.rezero_ground_truth = s.GetList("rezero_ground_truth_channels", r.rezero_ground_truth,
                                    "ground-truth channels re-zeroed to start at the origin (first pose subtracted, rotated by -theta0)");
  r.reference_pose = s.GetList("reference_pose_channels", r.reference_pose,
                               "LCM channels with another estimator's poses (staff SLAM)");
  r.velocity_command = s.GetList("velocity_command_channels", r.velocity_command,
                                 "LCM channels whose twist2D_t messages are velocity commands");
  o.carmen_max_range_m = s.GetDouble("carmen_max_range_m", o.carmen_max_range_m,
                                     "CARMEN FLASER range limit when the log's PARAM lines do not give one [m]", 0.1, 1000.0);
  o.reorder_window_us = static_cast<int64_t>(
      1e6 * s.GetDouble("reorder_window_s", o.reorder_window_us * 1e-6,
                        "LCM log records are re-sorted by event time within this window [s]", 0.0, 10.0));
  return o;
}

std::string DetectFormat(const std::string& path) {
  std::string cases;
  if (IsPlanningCasesPath(path, &cases)) return cases;
  if (!std::filesystem::is_regular_file(path)) throw std::runtime_error(path + ": no such file");
  if (IsMapFile(path)) return "map";
  const auto ends_with = [&path](const std::string& s) {
    return path.size() >= s.size() && path.compare(path.size() - s.size(), s.size(), s) == 0;
  };
  if (ends_with(".rawlog") || ends_with(".rawlog.gz")) return "rawlog";
  unsigned char head[4] = {0, 0, 0, 0};
  {
    std::ifstream in(path, std::ios::binary);
    in.read(reinterpret_cast<char*>(head), 4);
  }
  const uint32_t word = (uint32_t(head[0]) << 24) | (uint32_t(head[1]) << 16) | (uint32_t(head[2]) << 8) | head[3];
  if (word == LcmLogReader::kSyncWord) return "lcm_log";
  // Text (possibly gzip-compressed): CARMEN logs start with comments or message names.
  gzFile f = gzopen(path.c_str(), "rb");
  if (f) {
    char buf[256] = {0};
    const int n = gzread(f, buf, sizeof buf - 1);
    gzclose(f);
    if (n > 0) {
      const std::string text(buf, n);
      for (const char* tag : {"#", "PARAM", "ODOM", "FLASER", "RLASER", "ROBOTLASER", "RAWLASER", "TRUEPOS", "SYNC"}) {
        if (text.rfind(tag, 0) == 0) return "carmen";
      }
    }
  }
  throw std::runtime_error(path + ": unrecognised format (not an LCM log, MRPT rawlog, CARMEN log or map); set source.type");
}

std::unique_ptr<Source> OpenSource(const SourceOptions& options) {
  const std::string type = options.type == "auto" ? DetectFormat(options.path) : options.type;
  if (type == "lcm_log") return std::make_unique<LcmLogSource>(options);
  if (type == "rawlog") return std::make_unique<RawlogSource>(options);
  if (type == "carmen") return std::make_unique<CarmenSource>(options);
  if (type == "map") return std::make_unique<MapSource>(options.path);
  if (type == "astar_cases" || type == "movingai") return std::make_unique<PlanningCasesSource>(options.path, type);
  throw std::runtime_error("source type '" + type + "' is not known");
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
    case EventKind::kOther: return "other";
  }
  return "?";
}

}  // namespace mbot::drivers
