#include "mbot/drivers/source_options.hpp"

#include <zlib.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

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
#include "sim_source.hpp"

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

// "x, y, theta_deg" → a pose (theta in radians).
motion::Pose2D ParsePoseKey(config::Section& s, const std::string& key, const std::vector<std::string>& items) {
  if (items.size() != 3) {
    s.Fail(key, "expected x, y, theta_deg (3 numbers), got " + std::to_string(items.size()) + " items");
  }
  double v[3];
  for (int i = 0; i < 3; ++i) {
    char* end = nullptr;
    v[i] = std::strtod(items[i].c_str(), &end);
    if (*end != '\0' || !std::isfinite(v[i])) s.Fail(key, "expected a finite number, got '" + items[i] + "'");
  }
  return {v[0], v[1], motion::WrapAngle(v[2] * M_PI / 180.0)};
}

}  // namespace

SimSourceOptions ParseSimSourceOptions(config::Section& s, const std::string& world_path) {
  // Every key is documented as the simulator's: they exist only when the source is the simulator.
  const auto doc = [](const char* text) { return std::string("simulator: ") + text; };
  SimSourceOptions o;
  const std::vector<std::string> start =
      s.GetList("start", {}, doc("where the robot starts, in the world frame: x [m], y [m], theta [deg], or 'random' "
                                 "(a seeded draw from the reachable free space); default: the arena's 'start' pose "
                                 "(required for a map world)"));
  o.random_start_clearance_m = s.GetDouble("random_start_clearance_m", o.random_start_clearance_m,
                                           doc("start = random keeps this far from every wall [m]"), 0.0, 10.0);
  if (start.size() == 1 && start[0] == "random") {
    o.random_start = true;
  } else if (!start.empty()) {
    o.start = ParsePoseKey(s, "start", start);
  } else if (!s.describing() && !EndsWith(world_path, ".arena")) {
    s.Fail("start", "required: the world '" + world_path + "' is a map, which names no start pose");
  }
  o.duration_s = s.GetDouble("duration_s", o.duration_s, doc("simulated time after which the run ends [s]"), 0.001, 1e6);
  o.realtime_factor = s.GetDouble("realtime_factor", o.realtime_factor,
                                  doc("0: as fast as possible; else simulated time runs this many times the wall clock "
                                      "(1 for the simulated robot on the LCM bus)"), 0.0, 1000.0);
  if (o.realtime_factor > 0 && o.realtime_factor < 0.01) s.Fail("realtime_factor", "must be 0 (off) or at least 0.01");

  SimRobotOptions& r = o.robot;
  r.physics_dt_s = s.GetDouble("physics_dt_s", r.physics_dt_s, doc("integration step of the motion [s]"), 1e-4, 0.02);
  r.footprint_radius_m =
      s.GetDouble("footprint_radius_m", r.footprint_radius_m,
                  doc("radius of the robot's disc footprint; touching a wall with it stops the robot [m]"), 0.01, 1.0);
  r.left_motor_gain =
      s.GetDouble("left_motor_gain", r.left_motor_gain,
                  doc("true left wheel speed / the speed the motor model gives its duty (per-wheel difference)"), 0.5, 1.5);
  r.right_motor_gain = s.GetDouble("right_motor_gain", r.right_motor_gain,
                                   doc("true right wheel speed / the speed the motor model gives its duty"), 0.5, 1.5);
  r.motor_time_constant_s =
      s.GetDouble("motor_time_constant_s", r.motor_time_constant_s,
                  doc("first-order lag of a wheel's speed behind its duty's steady state [s]"), 0.0, 1.0);
  r.slip_stddev = s.GetDouble("slip_stddev", r.slip_stddev,
                              doc("relative error of each wheel's ground speed against its rotation (std. dev.)"), 0.0, 0.5);
  r.slip_interval_s =
      s.GetDouble("slip_interval_s", r.slip_interval_s, doc("how often each wheel's slip is redrawn [s]"), 0.001, 10.0);
  const double firmware_rate_hz =
      s.GetDouble("firmware_rate_hz", 1.0 / r.controller.dt_s,
                  doc("rate of the firmware's wheel-speed controller and its encoder, wheel-speed, odometry and PWM "
                      "messages [Hz]"),
                  5.0, 1000.0);
  r.controller.dt_s = 1.0 / firmware_rate_hz;
  r.ground_truth_rate_hz =
      s.GetDouble("ground_truth_rate_hz", r.ground_truth_rate_hz, doc("rate of the TRUE_POSE messages [Hz]"), 1.0, 1000.0);

  SimImuOptions& imu = r.imu;
  imu.rate_hz = s.GetDouble("imu_rate_hz", imu.rate_hz, doc("rate of the IMU messages [Hz]"), 1.0, 1000.0);
  imu.gyro_noise_rad_s = s.GetDouble("gyro_noise_rad_s", imu.gyro_noise_rad_s,
                                     doc("white noise of each gyro sample, standard deviation [rad/s]"), 0.0, 1.0);
  imu.gyro_bias_initial_rad_s = s.GetDouble("gyro_bias_initial_rad_s", imu.gyro_bias_initial_rad_s,
                                            doc("standard deviation of the gyro bias at start [rad/s]"), 0.0, 1.0);
  imu.gyro_bias_walk_rad_s_sqrt_s = s.GetDouble("gyro_bias_walk_rad_s_sqrt_s", imu.gyro_bias_walk_rad_s_sqrt_s,
                                                doc("random walk of the gyro bias [rad/s/sqrt(s)]"), 0.0, 1.0);

  SimLidarOptions& l = r.lidar;
  l.rate_hz = s.GetDouble("lidar_rate_hz", l.rate_hz, doc("lidar revolutions per second [Hz]"), 0.5, 100.0);
  l.beams = static_cast<int>(s.GetInt("lidar_beams", l.beams, doc("lidar beams per revolution"), 8, 100000));
  l.max_range_m = s.GetDouble("lidar_max_range_m", l.max_range_m,
                              doc("lidar range limit; farther walls give no return [m]"), 0.5, 100.0);
  l.min_range_m =
      s.GetDouble("lidar_min_range_m", l.min_range_m, doc("closer lidar returns are dropped [m]"), 0.0, 10.0);
  if (l.min_range_m >= l.max_range_m) s.Fail("lidar_min_range_m", "must be below lidar_max_range_m");
  l.range_noise_m =
      s.GetDouble("lidar_range_noise_m", l.range_noise_m, doc("lidar range noise, standard deviation [m]"), 0.0, 1.0);
  l.dropout =
      s.GetDouble("lidar_dropout", l.dropout, doc("probability that a lidar beam gives no return"), 0.0, 1.0);
  return o;
}

LiveSourceOptions ParseLiveSourceOptions(config::Section& s) {
  const auto doc = [](const char* text) { return std::string("lcm_live: ") + text; };
  LiveSourceOptions o;
  o.channels = s.GetList("channels", o.channels, doc("channels to subscribe to"));
  o.duration_s = s.GetDouble("duration_s", o.duration_s, doc("the run ends after this long (0: never) [s]"), 0.0, 1e7);
  o.end_after_silence_s = s.GetDouble("end_after_silence_s", o.end_after_silence_s,
                                      doc("the run ends when no message arrived for this long (0: never) [s]"), 0.0, 1e7);
  o.stale_sensor_s = s.GetDouble("stale_sensor_s", o.stale_sensor_s,
                                 doc("a watched channel silent this long stops the robot [s]"), 0.01, 1e4);
  o.watched = s.GetList("watched_channels", o.watched, doc("channels whose silence stops the robot"));
  o.command_channel = s.GetString("command_channel", o.command_channel, doc("velocity commands go out here"));
  o.report_every_s = s.GetDouble("report_every_s", o.report_every_s, doc("log the loop rate and latency this often (0: never) [s]"), 0.0, 1e6);
  return o;
}

SourceOptions ParseSourceOptions(config::Section& s) {
  SourceOptions o;
  o.type = s.GetChoice("type", o.type, {"auto", "lcm_log", "rawlog", "carmen", "map", "astar_cases", "movingai", "motor_csv", "sim", "lcm_live"},
                       "input format; auto detects it from the file's content (an .arena file is the simulator's world); "
                       "lcm_live: a robot on the LCM bus");
  const bool live = o.type == "lcm_live";
  if (live || s.describing()) {
    o.path = s.GetString("url", kDefaultLcmUrl, "lcm_live: the LCM URL (ttl=0 keeps the traffic on this machine)");
    o.live = ParseLiveSourceOptions(s);
  }
  if (!live) {
    o.path = s.RequirePath("path", "the dataset to read (LCM log, MRPT rawlog, CARMEN log, map file, botlab A* poses file or folder, Moving AI .scen), or the simulator's world (.arena or a map)");
  }
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
  // The simulator's keys exist only for the simulator (elsewhere they are unknown keys); --list-stages
  // (describe mode) documents them too.
  if (o.type == "sim" || (o.type == "auto" && EndsWith(o.path, ".arena")) || s.describing()) {
    o.sim = ParseSimSourceOptions(s, o.path);
  }
  return o;
}

std::string DetectFormat(const std::string& path) {
  std::string cases;
  if (IsPlanningCasesPath(path, &cases)) return cases;
  if (!std::filesystem::is_regular_file(path)) throw std::runtime_error(path + ": no such file");
  if (EndsWith(path, ".arena")) return "sim";
  if (IsMapFile(path)) return "map";
  if (EndsWith(path, ".rawlog") || EndsWith(path, ".rawlog.gz")) return "rawlog";
  if (EndsWith(path, ".csv") && IsMotorSamplesFile(path)) return "motor_csv";
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
  throw std::runtime_error(path + ": unrecognised format (not an LCM log, MRPT rawlog, CARMEN log, map or arena); set source.type");
}

std::unique_ptr<Source> OpenSource(const SourceOptions& options) {
  const std::string type = options.type == "auto" ? DetectFormat(options.path) : options.type;
  if (type == "lcm_log") return std::make_unique<LcmLogSource>(options);
  if (type == "rawlog") return std::make_unique<RawlogSource>(options);
  if (type == "carmen") return std::make_unique<CarmenSource>(options);
  if (type == "map") return std::make_unique<MapSource>(options.path);
  if (type == "astar_cases" || type == "movingai") return std::make_unique<PlanningCasesSource>(options.path, type);
  if (type == "sim") return std::make_unique<SimSource>(options);
  if (type == "motor_csv") return std::make_unique<MotorSamplesSource>(options.path);
  if (type == "lcm_live") return std::make_unique<LcmLiveSource>(options);
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
    case EventKind::kWheelSpeed: return "wheel speed";
    case EventKind::kMotorSample: return "motor sample";
    case EventKind::kCollision: return "collision";
    case EventKind::kPoseEstimate: return "pose estimate";
    case EventKind::kPath: return "path";
    case EventKind::kSlamStatus: return "SLAM status";
    case EventKind::kMissionStatus: return "mission status";
    case EventKind::kParticles: return "particles";
    case EventKind::kOther: return "other";
  }
  return "?";
}

}  // namespace mbot::drivers
