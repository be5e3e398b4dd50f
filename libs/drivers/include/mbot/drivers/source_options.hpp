// [source]: which dataset to read and how to interpret its channels.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "mbot/drivers/sim_source_options.hpp"
#include "mbot/drivers/source.hpp"

namespace mbot::config {
class Section;
}

namespace mbot::drivers {

// How channel names map to roles. Pose-typed messages (pose_xyt_t, odometry_t, pose2D_t share one
// layout) get their meaning from the channel they arrive on.
struct ChannelRoles {
  std::vector<std::string> odometry = {"ODOMETRY", "MBOT_ODOMETRY"};
  std::vector<std::string> ground_truth = {"TRUE_POSE", "GROUND_TRUTH_POSE"};
  // Ground-truth channels re-zeroed as the botlab README says: subtract the first pose, rotate by -θ0.
  std::vector<std::string> rezero_ground_truth = {"GROUND_TRUTH_POSE"};
  std::vector<std::string> reference_pose = {"SLAM_POSE"};
  std::vector<std::string> velocity_command = {"MBOT_VEL_CMD"};
};

// [source] type = lcm_live: a robot (or the simulated one) on the LCM bus, in wall-clock time.
struct LiveSourceOptions {
  // The robot's channels the autonomy listens to (current mbot_lcm_msgs names).
  std::vector<std::string> channels = {"LIDAR", "MBOT_ODOMETRY", "MBOT_ENCODERS", "MBOT_IMU",
                                       "MBOT_TIMESYNC", "CONTROLLER_PATH", "MBOT_SYSTEM_RESET"};
  double duration_s = 0.0;             // 0: until Ctrl-C or a stage ends the run
  double end_after_silence_s = 0.0;    // > 0: the run ends when nothing arrived for this long
  // A watched channel silent this long is reported and the robot stopped (zero velocity published,
  // commands held back) until it is back.
  double stale_sensor_s = 1.0;
  std::vector<std::string> watched = {"LIDAR", "MBOT_ODOMETRY"};
  std::string command_channel = "MBOT_VEL_CMD";
  double report_every_s = 10.0;        // a line with the loop rate and latency this often (0: never)
};

struct SourceOptions {
  std::string type = "auto";  // auto, lcm_log, rawlog, carmen, map, astar_cases, movingai, sim, lcm_live
  std::string path;           // required; for sim, the world file; for lcm_live, the LCM URL
  ChannelRoles roles;
  // CARMEN logs with old FLASER lines give no range limit; beams at or beyond it are no-returns.
  double carmen_max_range_m = 81.0;
  // LCM log records are re-sorted by event time within this window (lcm-logger writes them in
  // arrival order, which can run a few ms backwards).
  int64_t reorder_window_us = 100000;
  // Seed of the simulator's noise ([pipeline] seed, copied here by the pipeline; not a [source] key).
  uint64_t seed = 1;
  // The simulator's options: read only when the source is the simulator (type = sim, or auto with
  // an `.arena` path).
  SimSourceOptions sim;
  LiveSourceOptions live;  // read only when type = lcm_live
};

// Reads [source]. Throws config::ConfigError naming the key on bad values.
SourceOptions ParseSourceOptions(config::Section& section);
// The lcm_live keys of [source].
LiveSourceOptions ParseLiveSourceOptions(config::Section& section);

// Opens the input named by the options, detecting the format from its content when type = auto.
// The simulator (type sim) is also a Sink: dynamic_cast the source to drivers::Sink to drive it.
// Throws std::runtime_error naming the path when it cannot be read or recognised.
std::unique_ptr<Source> OpenSource(const SourceOptions& options);

// The format OpenSource would pick for `path` ("lcm_log", "rawlog", "carmen", "map", "astar_cases",
// "movingai", "sim" for an `.arena` world).
std::string DetectFormat(const std::string& path);

}  // namespace mbot::drivers
