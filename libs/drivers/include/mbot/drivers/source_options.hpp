// [source]: which dataset to read and how to interpret its channels.
#pragma once

#include <memory>
#include <string>
#include <vector>

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
  std::string type = "auto";  // auto, lcm_log, rawlog, carmen, map, astar_cases, movingai
  std::string path;           // required
  ChannelRoles roles;
  // CARMEN logs with old FLASER lines give no range limit; beams at or beyond it are no-returns.
  double carmen_max_range_m = 81.0;
  // LCM log records are re-sorted by event time within this window (lcm-logger writes them in
  // arrival order, which can run a few ms backwards).
  int64_t reorder_window_us = 100000;
};

// Reads [source]. Throws config::ConfigError naming the key on bad values.
SourceOptions ParseSourceOptions(config::Section& section);

// Opens the input named by the options, detecting the format from its content when type = auto.
// Throws std::runtime_error naming the path when it cannot be read or recognised.
std::unique_ptr<Source> OpenSource(const SourceOptions& options);

// The format OpenSource would pick for `path` ("lcm_log", "rawlog", "carmen", "map", "astar_cases",
// "movingai").
std::string DetectFormat(const std::string& path);

}  // namespace mbot::drivers
