// The `slam` stage's options, parsed strictly from its INI section. Kept apart from the stage so
// the competition's closed loop can build the same SLAM from the same keys.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "mbot/mapping/slam.hpp"
#include "mbot/mapping/moving_scan.hpp"
#include "mbot/motion/odometry_perturbation.hpp"
#include "mbot/motion/wheel_odometry.hpp"

namespace mbot::config {
class Section;
}

namespace mbot::app {

struct SlamStageOptions {
  mapping::SlamOptions slam;
  mapping::ScanOptions scan;
  std::string map_file;  // localization: the known map
  // Inputs.
  std::string lidar_channel, odometry_channel, ground_truth_channel, reference_channel;  // "" = first seen
  bool encoder_odometry = false;  // odometry from encoder ticks instead of an odometry channel
  motion::WheelOdometryOptions wheels;
  bool mapping_poses_from_reference = false;  // mapping-only: reference channel instead of ground truth
  bool truth_is_reference = false;            // score against the reference channel (CARMEN's corrected poses)
  bool lidar_pose_from_scan = true;           // the sensor pose the source gives (rawlog, CARMEN), else lidar_pose
  motion::Pose2D lidar_pose;
  std::string time_base = "event";  // event | stamp | auto
  mapping::BeamTiming beam_timing = mapping::BeamTiming::kAuto;
  int64_t lidar_time_offset_us = 0;
  double max_pose_gap_s = 0.5;
  // Start.
  std::string initial = "origin";  // origin | odometry | ground_truth | reference | global | pose
  motion::Pose2D initial_pose;
  double initial_sigma_xy = 0.0, initial_sigma_theta = 0.0;
  double checkpoint_every_s = 0.0;  // 0: no checkpoints
  std::string checkpoint_file = "slam_checkpoint.ini";
  std::string resume_from;                        // a checkpoint INI (sets map_file and initial_pose)
  std::optional<motion::Pose2D> resume_odometry;  // the odometry the checkpoint was written at
  // Perturbations for robustness tests.
  motion::OdometryPerturbationOptions perturbation;
  // Outputs.
  int64_t score_from_us = 0;         // ATE counts scans from this long after the start
  int64_t score_max_latency_us = 0;  // ... that arrived at most this late (0: all)
  std::string map_basename = "slam_map";
  int png_scale = 2;
  int particles_every = 0;          // draw the particles every k-th scan on the PNG (0: never)
  int publish_particles_every = 0;  // emit SLAM_PARTICLES every k-th scan (0: never)
  int publish_map_every = 5;        // emit the map to later stages every k-th scan (0: never)
  double octomap_height_m = 0.3;    // wall height in the OctoMap (0: no .bt)
  bool tum_stamps = false;          // the TUM files and the relations use the scans' own stamps
  std::string relations_file;       // a .relations file to score the trajectory on ("" = none)
};

SlamStageOptions ParseSlamStageOptions(config::Section& s);

}  // namespace mbot::app
