#include "slam_config.hpp"

#include <cmath>

#include "mbot/common/config.hpp"
#include "mbot/motion/motion_config.hpp"

namespace mbot::app {
namespace {

// `count` comma-separated finite numbers, or nothing (an empty vector) when the key is absent.
std::vector<double> ParseNumbers(config::Section& s, const std::string& key, size_t count, const std::string& what,
                                 const std::string& doc) {
  const std::vector<std::string> v = s.GetList(key, {}, doc);
  if (v.empty()) return {};
  if (v.size() != count) s.Fail(key, "expected " + what);
  std::vector<double> out(count);
  for (size_t i = 0; i < count; ++i) {
    size_t used = 0;
    try {
      out[i] = std::stod(v[i], &used);
    } catch (...) {
      used = 0;
    }
    if (used != v[i].size() || !std::isfinite(out[i])) s.Fail(key, "'" + v[i] + "' is not a number");
  }
  return out;
}

motion::Pose2D ParsePose(config::Section& s, const std::string& key, const motion::Pose2D& def, const std::string& doc) {
  const std::vector<double> v = ParseNumbers(s, key, 3, "x, y, theta", doc + " (x [m], y [m], theta [rad])");
  return v.empty() ? def : motion::Pose2D{v[0], v[1], v[2]};
}

}  // namespace

SlamStageOptions ParseSlamStageOptions(config::Section& s) {
  SlamStageOptions o;
  mapping::SlamOptions& m = o.slam;
  const std::string mode = s.GetChoice("mode", "full_slam", {"full_slam", "localization", "mapping_only", "action_only"},
                                       "what runs: full SLAM, localization on map_file, mapping from known poses, "
                                       "or particles driven by odometry alone");
  m.mode = mode == "full_slam"      ? mapping::SlamMode::kFullSlam
           : mode == "localization" ? mapping::SlamMode::kLocalization
           : mode == "mapping_only" ? mapping::SlamMode::kMappingOnly
                                    : mapping::SlamMode::kActionOnly;
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
  o.mapping_poses_from_reference =
      s.GetChoice("mapping_poses", "ground_truth", {"ground_truth", "reference"},
                  "mapping-only: where the poses come from") == "reference";
  o.truth_is_reference = s.GetChoice("truth", "ground_truth", {"ground_truth", "reference"},
                                     "what metrics.json scores against") == "reference";
  const std::vector<std::string> lp = s.GetList("lidar_pose", {"auto"}, "sensor pose on the robot: auto (as the source says) or x, y, theta");
  if (lp.size() == 1 && lp[0] == "auto") {
    o.lidar_pose_from_scan = true;
  } else {
    o.lidar_pose_from_scan = false;
    o.lidar_pose = ParsePose(s, "lidar_pose", {}, "sensor pose on the robot");
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
      std::llround(s.GetDouble("lidar_time_offset_s", 0.0, "added to a scan's time (its last beam) before poses are looked up", -1.0, 1.0) * 1e6));
  o.max_pose_gap_s = s.GetDouble("max_pose_gap_s", 0.5, "largest gap in a pose series to interpolate across", 0.0);

  // Scan.
  o.scan.min_range_m = s.GetDouble("min_range_m", o.scan.min_range_m, "shorter returns are dropped", 0.0);
  o.scan.max_range_m = s.GetDouble("max_range_m", o.scan.max_range_m, "returns at or beyond this are misses (0: the sensor's maximum)", 0.0);
  o.scan.no_return_clear_m = s.GetDouble("no_return_clear_m", o.scan.no_return_clear_m, "a beam without return clears this far (0: not at all)", 0.0);

  // Mapper.
  mapping::MapperOptions& mp = m.mapper;
  mp.hit_odds = static_cast<int>(s.GetInt("hit_odds", mp.hit_odds, "log-odds added to a ray's end cell", 0, 127));
  mp.miss_odds = static_cast<int>(s.GetInt("miss_odds", mp.miss_odds, "log-odds removed from the cells a ray crosses", 0, 127));
  mp.resolution_m = s.GetDouble("resolution_m", mp.resolution_m, "cell size", 0.001, 10.0);
  mp.width_m = s.GetDouble("width_m", mp.width_m, "initial map width", 0.01);
  mp.height_m = s.GetDouble("height_m", mp.height_m, "initial map height", 0.01);
  mp.center_x_m = s.GetDouble("center_x_m", mp.center_x_m, "initial map centre x");
  mp.center_y_m = s.GetDouble("center_y_m", mp.center_y_m, "initial map centre y");
  mp.grow = s.GetBool("grow", mp.grow, "grow the map when scans reach its edge (false: clip)");

  // Action model.
  mapping::ActionModelOptions& a = m.action;
  a.k1 = s.GetDouble("k1", a.k1, "rotation noise: sigma = sqrt(k1 |rot|)", 0.0);
  a.k2 = s.GetDouble("k2", a.k2, "translation noise: sigma = sqrt(k2 |trans|)", 0.0);
  a.min_sigma_trans_m = s.GetDouble("min_sigma_trans_m", a.min_sigma_trans_m, "translation noise floor", 0.0);
  a.min_sigma_rot_rad = s.GetDouble("min_sigma_rot_rad", a.min_sigma_rot_rad, "rotation noise floor", 0.0);
  a.min_trans_m = s.GetDouble("min_trans_m", a.min_trans_m, "the filter updates after this much translation", 0.0);
  a.min_rot_rad = s.GetDouble("min_rot_rad", a.min_rot_rad, "... or this much rotation", 0.0);

  // Sensor model.
  mapping::SensorModelOptions& sm = m.sensor;
  sm.kind = s.GetChoice("sensor_model", "likelihood_field", {"likelihood_field", "simplified"},
                        "Gaussian of the end point's obstacle distance, or the botlab simplified likelihood field") ==
                    "likelihood_field"
                ? mapping::SensorModelKind::kLikelihoodField
                : mapping::SensorModelKind::kSimplifiedField;
  sm.ray_stride = static_cast<int>(s.GetInt("ray_stride", sm.ray_stride, "use every k-th ray in the sensor model", 1, 1000));
  sm.sigma_m = s.GetDouble("sigma_m", sm.sigma_m, "likelihood field: end-point noise", 0.001);
  sm.max_distance_m = s.GetDouble("max_distance_m", sm.max_distance_m, "likelihood field: distances clamp here", 0.001);
  sm.random_weight = s.GetDouble("random_weight", sm.random_weight, "likelihood field: uniform share for unexplained returns", 0.0);
  sm.log_scale = s.GetDouble("log_scale", sm.log_scale, "multiplies a scan's log-likelihood (tempers beam correlation)", 1e-6);
  sm.odds_scale = s.GetDouble("odds_scale", sm.odds_scale, "simplified field: log-likelihood per log-odds unit", 0.0);
  sm.neighbour_weight = s.GetDouble("neighbour_weight", sm.neighbour_weight, "simplified field: weight of the cell before/after", 0.0, 1.0);
  sm.inlier_distance_m = s.GetDouble("inlier_distance_m", sm.inlier_distance_m, "a ray fits the map when it ends this close to an obstacle", 0.0);

  // Particle filter.
  mapping::ParticleFilterOptions& f = m.filter;
  f.particles = static_cast<int>(s.GetInt("particles", f.particles, "particles", 1, 10'000'000));
  f.top_fraction = s.GetDouble("top_fraction", f.top_fraction, "the estimate averages this share of the best particles", 1e-6, 1.0);
  f.threads = static_cast<int>(s.GetInt("threads", f.threads, "threads for the particles (0: all cores)", 0, 256));
  f.global_particles = static_cast<int>(s.GetInt("global_particles", f.global_particles, "particles for global localization", 1, 10'000'000));
  f.converged_spread_m = s.GetDouble("converged_spread_m", f.converged_spread_m, "a global search has converged below this spread", 0.0);
  const std::vector<double> box = ParseNumbers(s, "global_region", 4, "min_x, max_x, min_y, max_y",
      "global localization starts from the free cells inside this box (min_x, max_x, min_y, max_y [m]); empty: the whole map");
  if (!box.empty()) {
    if (!(box[0] < box[1] && box[2] < box[3])) s.Fail("global_region", "needs min_x < max_x and min_y < max_y");
    f.global_region = mapping::SearchBox{box[0], box[1], box[2], box[3]};
  }
  f.global_min_ess_fraction = s.GetDouble("global_min_ess_fraction", f.global_min_ess_fraction,
                                          "a global search tempers the scan likelihood to keep this share of particles effective (0: off)", 0.0, 1.0);
  f.converged_inlier_fraction = s.GetDouble("converged_inlier_fraction", f.converged_inlier_fraction,
                                            "a settled global search is accepted when this share of the scan fits the map, else it starts again", 0.0, 1.0);
  f.augmented = s.GetBool("augmented", m.mode == mapping::SlamMode::kLocalization, "augmented MCL: inject random particles when the fit drops");
  f.alpha_slow = s.GetDouble("alpha_slow", f.alpha_slow, "augmented MCL: long-term fit average rate", 0.0, 1.0);
  f.alpha_fast = s.GetDouble("alpha_fast", f.alpha_fast, "augmented MCL: short-term fit average rate", 0.0, 1.0);
  f.max_injection = s.GetDouble("max_injection", f.max_injection, "augmented MCL: largest share replaced per update", 0.0, 1.0);
  f.lost_inlier_fraction = s.GetDouble("lost_inlier_fraction", f.lost_inlier_fraction, "lost when the estimate's inlier share stays below this", 0.0, 1.0);
  f.lost_fit_ratio = s.GetDouble("lost_fit_ratio", f.lost_fit_ratio, "... or the short-term scan fit below this share of the long-term one", 0.0, 1.0);
  f.lost_scans = static_cast<int>(s.GetInt("lost_scans", f.lost_scans, "... for this many updates in a row", 1, 1000000));
  f.relocalize_when_lost = s.GetBool("relocalize_when_lost", m.mode == mapping::SlamMode::kLocalization,
                                     "localization: spread the particles over the map again when lost");

  // Start.
  const std::vector<std::string> init = s.GetList("initial_pose", {"origin"},
      "origin | odometry | ground_truth | reference | global | x, y, theta");
  if (init.size() == 1 && (init[0] == "origin" || init[0] == "odometry" || init[0] == "ground_truth" ||
                           init[0] == "reference" || init[0] == "global")) {
    o.initial = init[0];
  } else {
    o.initial = "pose";
    o.initial_pose = ParsePose(s, "initial_pose", {}, "start pose");
  }
  if (o.initial == "global" && m.mode != mapping::SlamMode::kLocalization && !s.describing()) {
    s.Fail("initial_pose", "global needs mode = localization");
  }
  o.initial_sigma_xy = s.GetDouble("initial_sigma_xy_m", 0.0, "spread of the first particles around the start", 0.0);
  o.initial_sigma_theta = s.GetDouble("initial_sigma_theta_rad", 0.0, "heading spread of the first particles", 0.0);

  // Perturbations.
  auto& pert = o.perturbation;
  pert.noise_trans = s.GetDouble("odometry_noise_trans", 0.0, "injected odometry noise: sigma per metre of each step", 0.0);
  pert.noise_rot = s.GetDouble("odometry_noise_rot", 0.0, "injected heading noise: sigma per radian and metre of each step", 0.0);
  pert.kidnap_at_s = s.GetDouble("kidnap_at_s", -1.0, "from this time on, odometry is offset by kidnap_offset (< 0: never)");
  pert.kidnap_offset = ParsePose(s, "kidnap_offset", {1.0, 0.0, M_PI / 2}, "the kidnapping jump");

  // Outputs.
  o.score_from_us = static_cast<int64_t>(s.GetDouble("score_from_s", 0.0, "ATE counts scans from this long after the start", 0.0) * 1e6);
  o.score_max_latency_us = static_cast<int64_t>(
      s.GetDouble("score_max_latency_s", 0.0, "ATE skips scans that reached the logger later than this after their stamp "
                  "(the logged motion capture is stamped on arrival and is late too); 0: score all", 0.0) * 1e6);
  o.map_basename = s.GetString("map_basename", o.map_basename, "map files in output.dir: .map, .pgm/.yaml, .png, .bt");
  o.png_scale = static_cast<int>(s.GetInt("png_scale", o.png_scale, "pixels per map cell in the PNG", 1, 16));
  o.particles_every = static_cast<int>(s.GetInt("particles_every", o.particles_every, "draw the particles every k-th scan (0: never)", 0));
  o.publish_particles_every = static_cast<int>(s.GetInt("publish_particles_every", o.publish_particles_every,
                                                        "emit the particles (SLAM_PARTICLES) every k-th scan (0: never)", 0));
  o.publish_map_every = static_cast<int>(s.GetInt("publish_map_every", o.publish_map_every,
                                                  "emit the map to later stages (planner, explorer) every k-th scan (0: never); the pose goes every scan", 0));
  o.octomap_height_m = s.GetDouble("octomap_height_m", o.octomap_height_m, "wall height in the OctoMap .bt (0: none)", 0.0);
  return o;
}

}  // namespace mbot::app
