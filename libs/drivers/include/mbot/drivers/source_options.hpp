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

struct SourceOptions {
  std::string type = "auto";  // auto, lcm_log, rawlog, carmen, map, astar_cases, movingai, sim
  std::string path;           // required; for sim, the world file
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
};

// Reads [source]. Throws config::ConfigError naming the key on bad values.
SourceOptions ParseSourceOptions(config::Section& section);

// Opens the input named by the options, detecting the format from its content when type = auto.
// The simulator (type sim) is also a Sink: dynamic_cast the source to drivers::Sink to drive it.
// Throws std::runtime_error naming the path when it cannot be read or recognised.
std::unique_ptr<Source> OpenSource(const SourceOptions& options);

// The format OpenSource would pick for `path` ("lcm_log", "rawlog", "carmen", "map", "astar_cases",
// "movingai", "sim" for an `.arena` world).
std::string DetectFormat(const std::string& path);

}  // namespace mbot::drivers
