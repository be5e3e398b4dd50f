#include "slam_config.hpp"

#include <cmath>

#include "mbot/common/config.hpp"
#include "mbot/drivers/map_io.hpp"
#include "mbot/mapping/mapping_config.hpp"
#include "mbot/motion/motion_config.hpp"

namespace mbot::app {

SlamStageOptions ParseSlamStageOptions(config::Section& s) {
  SlamStageOptions o;
  o.slam = mapping::ParseSlamOptions(s);
  o.scan = mapping::ParseScanOptions(s);
  const mapping::SlamOptions& m = o.slam;
  o.map_file = s.GetPath("map_file", "", "localization: the known map (any format the map reader knows)");
  if (m.mode == mapping::SlamMode::kLocalization && o.map_file.empty() && !s.describing()) {
    s.Fail("map_file", "localization mode needs a map_file");
  }

  // Inputs.
  o.lidar_channel = s.GetString("lidar_channel", "", "lidar channel ('' = the first one seen)");
  const std::string odo = s.GetChoice("odometry", "channel", {"channel", "encoders"},
                                      "odometry from an odometry channel or integrated from encoder ticks");
  o.encoder_odometry = odo == "encoders";
  o.odometry_channel = s.GetString("odometry_channel", "", "odometry channel ('' = the first one seen)");
  o.wheels = motion::ParseWheelConstants(s);  // used when odometry = encoders
  o.ground_truth_channel = s.GetString("ground_truth_channel", "", "ground-truth channel ('' = the first one seen)");
  o.reference_channel = s.GetString("reference_channel", "", "reference-pose channel ('' = the first one seen)");
  o.mapping_poses_from_reference = s.GetChoice("mapping_poses", "ground_truth", {"ground_truth", "reference"},
                                               "mapping-only: where the poses come from") == "reference";
  o.truth_is_reference = s.GetChoice("truth", "ground_truth", {"ground_truth", "reference"},
                                     "what metrics.json scores against") == "reference";
  const std::vector<std::string> lp =
      s.GetList("lidar_pose", {"auto"}, "sensor pose on the robot: auto (as the source says) or x, y, theta_deg");
  if (lp.size() == 1 && lp[0] == "auto") {
    o.lidar_pose_from_scan = true;
  } else {
    o.lidar_pose_from_scan = false;
    const config::PoseValue p = s.GetPose("lidar_pose", {}, "sensor pose on the robot");
    o.lidar_pose = {p.x_m, p.y_m, p.theta_rad};
  }
  o.time_base = s.GetChoice("time_base", "event", {"event", "stamp", "auto"},
                            "place messages at their arrival (event) times, as the log's motion capture is, or at "
                            "their own stamps (auto: where a channel's stamps share the log's clock)");
  o.beam_timing = s.GetEnum("beam_timing", o.beam_timing,
                            {{"auto", mapping::BeamTiming::kAuto},
                             {"beams", mapping::BeamTiming::kBeams},
                             {"spread", mapping::BeamTiming::kSpread},
                             {"none", mapping::BeamTiming::kNone}},
                            "per-beam time: the beams' own times, spread evenly over the time since the last scan, "
                            "or none (all at the scan time); auto picks the first that applies");
  o.lidar_time_offset_us = static_cast<int64_t>(
      std::llround(s.GetDouble("lidar_time_offset_s", 0.0,
                               "added to a scan's time (its last beam) before poses are looked up", -1.0, 1.0) *
                   1e6));
  o.max_pose_gap_s = s.GetDouble("max_pose_gap_s", 0.5, "largest gap in a pose series to interpolate across", 0.0);

  // Start.
  const std::vector<std::string> init =
      s.GetList("initial_pose", {"origin"}, "origin | odometry | ground_truth | reference | global | x, y, theta_deg");
  if (init.size() == 1 && (init[0] == "origin" || init[0] == "odometry" || init[0] == "ground_truth" ||
                           init[0] == "reference" || init[0] == "global")) {
    o.initial = init[0];
  } else {
    o.initial = "pose";
    const config::PoseValue p = s.GetPose("initial_pose", {}, "start pose");
    o.initial_pose = {p.x_m, p.y_m, p.theta_rad};
  }
  if (o.initial == "global" && m.mode != mapping::SlamMode::kLocalization && !s.describing()) {
    s.Fail("initial_pose", "global needs mode = localization");
  }
  o.initial_sigma_xy = s.GetDouble("initial_sigma_xy_m", 0.0, "spread of the first particles around the start", 0.0);
  o.initial_sigma_theta = s.GetDouble("initial_sigma_theta_rad", 0.0, "heading spread of the first particles", 0.0);

  // Checkpoints: the map and pose written every so often, and a run resumed from them.
  o.checkpoint_every_s = s.GetDouble("checkpoint_every_s", 0.0,
                                     "write the map and pose to checkpoint_file this often, in the stream's time, so "
                                     "a killed run can resume (0: never) [s]",
                                     0.0, 1e6);
  o.checkpoint_file = s.GetString("checkpoint_file", "slam_checkpoint.ini",
                                  "the checkpoint's INI, in the output folder (its map beside it, as .map)");
  o.resume_from = s.GetPath("resume_from", "",
                            "a checkpoint INI to start from: its map becomes map_file and its pose the initial_pose "
                            "(for full SLAM the map keeps growing)");
  if (!o.resume_from.empty() && !s.describing()) {
    if (m.mode == mapping::SlamMode::kMappingOnly || m.mode == mapping::SlamMode::kActionOnly) {
      s.Fail("resume_from", "needs mode = full_slam or localization (a map to localize in)");
    }
    try {
      const drivers::SlamCheckpoint c = drivers::ReadSlamCheckpoint(o.resume_from);
      o.map_file = c.map_path;
      o.initial = "pose";
      o.initial_pose = c.pose;
      o.resume_odometry = c.odometry;
    } catch (const std::exception& e) {
      s.Fail("resume_from", e.what());
    }
  }

  // Perturbations.
  auto& pert = o.perturbation;
  pert.noise_trans =
      s.GetDouble("odometry_noise_trans", 0.0, "injected odometry noise: sigma per metre of each step", 0.0);
  pert.noise_rot =
      s.GetDouble("odometry_noise_rot", 0.0, "injected heading noise: sigma per radian and metre of each step", 0.0);
  pert.kidnap_at_s =
      s.GetDouble("kidnap_at_s", -1.0, "from this time on, odometry is offset by kidnap_offset (< 0: never)");
  const config::PoseValue k = s.GetPose("kidnap_offset", {1.0, 0.0, M_PI / 2}, "the kidnapping jump");
  pert.kidnap_offset = {k.x_m, k.y_m, k.theta_rad};

  // Outputs.
  o.score_from_us = static_cast<int64_t>(
      s.GetDouble("score_from_s", 0.0, "ATE counts scans from this long after the start", 0.0) * 1e6);
  o.score_max_latency_us = static_cast<int64_t>(
      s.GetDouble("score_max_latency_s", 0.0,
                  "ATE skips scans that reached the logger later than this after their stamp "
                  "(the logged motion capture is stamped on arrival and is late too); 0: score all",
                  0.0) *
      1e6);
  o.map_basename = s.GetString("map_basename", o.map_basename, "map files in output.dir: .map, .pgm/.yaml, .png, .bt");
  o.png_scale = static_cast<int>(s.GetInt("png_scale", o.png_scale, "pixels per map cell in the PNG", 1, 16));
  o.particles_every = static_cast<int>(
      s.GetInt("particles_every", o.particles_every, "draw the particles every k-th scan (0: never)", 0));
  o.publish_particles_every =
      static_cast<int>(s.GetInt("publish_particles_every", o.publish_particles_every,
                                "emit the particles (SLAM_PARTICLES) every k-th scan (0: never)", 0));
  o.publish_map_every = static_cast<int>(s.GetInt(
      "publish_map_every", o.publish_map_every,
      "emit the map to later stages (planner, explorer) every k-th scan (0: never); the pose goes every scan", 0));
  o.octomap_height_m =
      s.GetDouble("octomap_height_m", o.octomap_height_m, "wall height in the OctoMap .bt (0: none)", 0.0);
  o.tum_stamps = s.GetChoice("tum_time", "event", {"event", "stamp"},
                             "times in the TUM files and for the relations: each scan's event time, or its own "
                             "stamp (CARMEN logs read in file order)") == "stamp";
  o.relations_file =
      s.GetPath("relations", "", "score slam.tum on this Kuemmerle et al. .relations file (metrics.json 'relations')");
  return o;
}

}  // namespace mbot::app
