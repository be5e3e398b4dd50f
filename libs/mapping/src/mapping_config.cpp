#include "mbot/mapping/mapping_config.hpp"

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "mbot/common/config.hpp"

namespace mbot::mapping {
namespace {

// `count` comma-separated finite numbers, or nothing (an empty vector) when the key is absent.
std::vector<double> Numbers(config::Section& s, const std::string& key, size_t count, const std::string& what,
                            const std::string& doc) {
  const std::vector<std::string> v = s.GetList(key, {}, doc);
  if (v.empty()) return {};
  if (v.size() != count) s.Fail(key, "expected " + what);
  std::vector<double> out(count);
  for (size_t i = 0; i < count; ++i) {
    char* end = nullptr;
    out[i] = std::strtod(v[i].c_str(), &end);
    if (*end != '\0' || !std::isfinite(out[i])) s.Fail(key, "'" + v[i] + "' is not a finite number");
  }
  return out;
}

}  // namespace

ScanOptions ParseScanOptions(config::Section& s, const ScanOptions& defaults) {
  ScanOptions o = defaults;
  o.min_range_m = s.GetDouble("min_range_m", o.min_range_m, "shorter returns are dropped", 0.0);
  o.max_range_m =
      s.GetDouble("max_range_m", o.max_range_m, "returns at or beyond this are misses (0: the sensor's maximum)", 0.0);
  o.no_return_clear_m = s.GetDouble("no_return_clear_m", o.no_return_clear_m,
                                    "a beam without return clears this far (0: not at all)", 0.0);
  o.smooth_beams = static_cast<int>(s.GetInt(
      "smooth_beams", o.smooth_beams,
      "each return is the mean of those up to this many beams either side on the same surface (0: off)", 0, 50));
  o.smooth_max_step_m = s.GetDouble("smooth_max_step_m", o.smooth_max_step_m,
                                    "smoothing: neighbours within this of a return are on its surface", 0.0);

  return o;
}

MapperOptions ParseMapperOptions(config::Section& s, const MapperOptions& defaults) {
  MapperOptions mp = defaults;
  mp.hit_odds = static_cast<int>(s.GetInt("hit_odds", mp.hit_odds, "log-odds added to a ray's end cell", 0, 127));
  mp.miss_odds =
      static_cast<int>(s.GetInt("miss_odds", mp.miss_odds, "log-odds removed from the cells a ray crosses", 0, 127));
  mp.resolution_m = s.GetDouble("resolution_m", mp.resolution_m, "cell size", 0.001, 10.0);
  mp.width_m = s.GetDouble("width_m", mp.width_m, "initial map width", 0.01, 1e5);
  mp.height_m = s.GetDouble("height_m", mp.height_m, "initial map height", 0.01, 1e5);
  mp.center_x_m = s.GetDouble("center_x_m", mp.center_x_m, "initial map centre x", -1e6, 1e6);
  mp.center_y_m = s.GetDouble("center_y_m", mp.center_y_m, "initial map centre y", -1e6, 1e6);
  // The grid these ask for must be one a computer can hold (2^28 cells, as for map files).
  const double cells = std::ceil(mp.width_m / mp.resolution_m) * std::ceil(mp.height_m / mp.resolution_m);
  if (cells > double(kMaxGridCells)) {
    s.Fail("width_m", "a " + std::to_string(mp.width_m) + " x " + std::to_string(mp.height_m) + " m map at " +
                          std::to_string(mp.resolution_m) + " m is more than 2^28 cells");
  }
  mp.grow = s.GetBool("grow", mp.grow, "grow the map when scans reach its edge (false: clip)");

  return mp;
}

ActionModelOptions ParseActionModelOptions(config::Section& s, const ActionModelOptions& defaults) {
  ActionModelOptions a = defaults;
  a.k1 = s.GetDouble("k1", a.k1, "rotation noise: sigma = sqrt(k1 |rot|)", 0.0);
  a.k2 = s.GetDouble("k2", a.k2, "translation noise: sigma = sqrt(k2 |trans|)", 0.0);
  a.min_sigma_trans_m = s.GetDouble("min_sigma_trans_m", a.min_sigma_trans_m, "translation noise floor", 0.0);
  a.min_sigma_rot_rad = s.GetDouble("min_sigma_rot_rad", a.min_sigma_rot_rad, "rotation noise floor", 0.0);
  a.min_trans_m = s.GetDouble("min_trans_m", a.min_trans_m, "the filter updates after this much translation", 0.0);
  a.min_rot_rad = s.GetDouble("min_rot_rad", a.min_rot_rad, "... or this much rotation", 0.0);

  return a;
}

SensorModelOptions ParseSensorModelOptions(config::Section& s, const SensorModelOptions& defaults) {
  SensorModelOptions sm = defaults;
  sm.kind = s.GetEnum(
      "sensor_model", sm.kind,
      {{"likelihood_field", SensorModelKind::kLikelihoodField}, {"simplified", SensorModelKind::kSimplifiedField}},
      "Gaussian of the end point's obstacle distance, or the botlab simplified likelihood field");
  sm.ray_stride =
      static_cast<int>(s.GetInt("ray_stride", sm.ray_stride, "use every k-th ray in the sensor model", 1, 1000));
  sm.sigma_m = s.GetDouble("sigma_m", sm.sigma_m, "likelihood field: end-point noise", 0.001);
  sm.max_distance_m = s.GetDouble("max_distance_m", sm.max_distance_m, "likelihood field: distances clamp here", 0.001);
  sm.random_weight =
      s.GetDouble("random_weight", sm.random_weight, "likelihood field: uniform share for unexplained returns", 0.0);
  sm.log_scale =
      s.GetDouble("log_scale", sm.log_scale, "multiplies a scan's log-likelihood (tempers beam correlation)", 1e-6);
  sm.odds_scale = s.GetDouble("odds_scale", sm.odds_scale, "simplified field: log-likelihood per log-odds unit", 0.0);
  sm.neighbour_weight = s.GetDouble("neighbour_weight", sm.neighbour_weight,
                                    "simplified field: weight of the cell before/after", 0.0, 1.0);
  sm.occupied_threshold = static_cast<int>(
      s.GetInt("sensor_occupied_threshold", sm.occupied_threshold,
               "cells with log-odds above this are the obstacles the sensor model measures distances to", -127, 126));
  sm.inlier_distance_m = s.GetDouble("inlier_distance_m", sm.inlier_distance_m,
                                     "a ray fits the map when it ends this close to an obstacle", 0.0);

  return sm;
}

ParticleFilterOptions ParseParticleFilterOptions(config::Section& s, SlamMode mode,
                                                 const ParticleFilterOptions& defaults) {
  ParticleFilterOptions f = defaults;
  f.particles = static_cast<int>(s.GetInt("particles", f.particles, "particles", 1, 10'000'000));
  f.top_fraction =
      s.GetDouble("top_fraction", f.top_fraction, "the estimate averages this share of the best particles", 1e-6, 1.0);
  f.threads = static_cast<int>(s.GetInt("threads", f.threads, "threads for the particles (0: all cores)", 0, 256));
  f.global_particles = static_cast<int>(
      s.GetInt("global_particles", f.global_particles, "particles for global localization", 1, 10'000'000));
  f.converged_spread_m =
      s.GetDouble("converged_spread_m", f.converged_spread_m, "a global search has converged below this spread", 0.0);
  const std::vector<double> box = Numbers(s, "global_region", 4, "min_x, max_x, min_y, max_y",
                                          "global localization starts from the free cells inside this box (min_x, "
                                          "max_x, min_y, max_y [m]); empty: the whole map");
  if (!box.empty()) {
    if (!(box[0] < box[1] && box[2] < box[3])) s.Fail("global_region", "needs min_x < max_x and min_y < max_y");
    f.global_region = SearchBox{box[0], box[1], box[2], box[3]};
  }
  f.global_min_ess_fraction = s.GetDouble(
      "global_min_ess_fraction", f.global_min_ess_fraction,
      "a global search tempers the scan likelihood to keep this share of particles effective (0: off)", 0.0, 1.0);
  f.converged_inlier_fraction = s.GetDouble(
      "converged_inlier_fraction", f.converged_inlier_fraction,
      "a settled global search is accepted when this share of the scan fits the map, else it starts again", 0.0, 1.0);
  f.augmented = s.GetBool("augmented", mode == SlamMode::kLocalization,
                          "augmented MCL: inject random particles when the fit drops");
  f.alpha_slow = s.GetDouble("alpha_slow", f.alpha_slow, "augmented MCL: long-term fit average rate", 0.0, 1.0);
  f.alpha_fast = s.GetDouble("alpha_fast", f.alpha_fast, "augmented MCL: short-term fit average rate", 0.0, 1.0);
  f.max_injection =
      s.GetDouble("max_injection", f.max_injection, "augmented MCL: largest share replaced per update", 0.0, 1.0);
  f.lost_inlier_fraction = s.GetDouble("lost_inlier_fraction", f.lost_inlier_fraction,
                                       "lost when the estimate's inlier share stays below this", 0.0, 1.0);
  f.lost_fit_ratio = s.GetDouble("lost_fit_ratio", f.lost_fit_ratio,
                                 "... or the short-term scan fit below this share of the long-term one", 0.0, 1.0);
  f.lost_scans =
      static_cast<int>(s.GetInt("lost_scans", f.lost_scans, "... for this many updates in a row", 1, 1000000));
  f.relocalize_when_lost = s.GetBool("relocalize_when_lost", mode == SlamMode::kLocalization,
                                     "localization: spread the particles over the map again when lost");
  return f;
}

GraphSlamOptions ParseGraphSlamOptions(config::Section& s, const GraphSlamOptions& defaults) {
  GraphSlamOptions g = defaults;
  auto num = [&](const char* key, double def, const char* doc, double lo, double hi) {
    return s.GetDouble(std::string("graph_") + key, def, doc, lo, hi);
  };
  auto count = [&](const char* key, int def, const char* doc, int lo, int hi) {
    return static_cast<int>(s.GetInt(std::string("graph_") + key, def, doc, lo, hi));
  };
  g.submap.resolution_m = num("resolution_m", g.submap.resolution_m, "submap cell size", 0.005, 1.0);
  g.submap.hit_odds = count("hit_odds", g.submap.hit_odds, "submaps: log-odds added to a ray's end cell", 0, 127);
  g.submap.miss_odds = count("miss_odds", g.submap.miss_odds, "submaps: log-odds removed along a ray", 0, 127);
  g.nodes_per_submap =
      count("nodes_per_submap", g.nodes_per_submap,
            "nodes inserted into a submap before the next starts (it is finished at twice this)", 1, 100000);
  g.field_sigma_m = num("field_sigma_m", g.field_sigma_m, "the matching field's Gaussian width", 0.001, 10.0);
  g.occupied_threshold = count("occupied_threshold", g.occupied_threshold,
                               "submap cells above this log-odds are obstacles for matching", -127, 126);
  g.point_spacing_m =
      num("point_spacing_m", g.point_spacing_m, "thin a scan's points to this spacing (0: all)", 0.0, 10.0);
  g.loop_point_spacing_m = num("loop_point_spacing_m", g.loop_point_spacing_m,
                               "thin a node's points to this spacing for the loop-closure search", 0.0, 10.0);
  g.min_points =
      count("min_points", g.min_points, "scans with fewer returns are not matched (they are counted)", 1, 100000);
  g.local_search = s.GetBool("graph_local_search", g.local_search,
                             "front end: correlative search before the Ceres fit (false: the fit alone)");
  // A search window: `<prefix>_m` and `<prefix>_rad`, ± around the start.
  auto window = [&](const std::string& prefix, SearchWindow* w, const std::string& what, double max_linear_m) {
    w->linear_m = num((prefix + "_m").c_str(), w->linear_m, (what + " search window, +-").c_str(), 0.0, max_linear_m);
    w->angular_rad =
        num((prefix + "_rad").c_str(), w->angular_rad, (what + " angular search window, +-").c_str(), 0.0, M_PI);
  };
  window("local_window", &g.local_window, "front end:", 10.0);
  g.recover_below = num("recover_below", g.recover_below,
                        "front end: a fit below this share of the running mean score is searched again over the "
                        "recovery window (0: never)",
                        0.0, 1.0);
  g.recover_gap_s = num("recover_gap_s", g.recover_gap_s,
                        "front end: an odometry gap longer than this around a scan, or a zeroed restart, searches the "
                        "recovery window whatever the fit scored (0: never)",
                        0.0, 3600.0);
  g.recover_margin = num("recover_margin", g.recover_margin,
                         "front end: a recovery is taken only where it scores this share of the running mean score "
                         "above the local fit (0: any better fit)",
                         0.0, 1.0);
  g.recover_slack_m = num("recover_slack_m", g.recover_slack_m,
                          "front end: a recovery searches no farther from the prediction than the odometry since "
                          "the last matched scan plus this (across an odometry gap, the clock's reach if farther; "
                          "0: the whole recovery window, with the clock bound off too)",
                          0.0, 20.0);
  g.recover_speed_factor =
      num("recover_speed_factor", g.recover_speed_factor,
          "front end: across an odometry gap, a recovery searches no farther than this times the robot's top speed "
          "(from the matched scans) times the gap or the time since the last matched scan, plus recover_slack_m; a "
          "zeroed restart searches the whole recovery window (0: so does a gap)",
          0.0, 100.0);
  window("recover_window", &g.recover_window, "front end: recovery", 20.0);
  g.front_min_constraint_ratio =
      num("front_min_constraint_ratio", g.front_min_constraint_ratio,
          "front end: a scan whose surfaces pin its position down along one direction only (weakest over strongest "
          "information below this: a corridor) keeps odometry's motion along it (0: trust the fit)",
          0.0, 1.0);
  g.refine.translation_weight =
      num("translation_weight", g.refine.translation_weight, "Ceres fit: pull towards the search's position", 0.0, 1e9);
  g.refine.rotation_weight =
      num("rotation_weight", g.refine.rotation_weight, "Ceres fit: pull towards the search's heading", 0.0, 1e9);
  g.refine.max_iterations = count("fit_iterations", g.refine.max_iterations, "Ceres fit: iterations", 1, 1000);
  g.node_distance_m =
      num("node_distance_m", g.node_distance_m, "a scan becomes a node after this much motion", 0.0, 100.0);
  g.node_angle_rad = num("node_angle_rad", g.node_angle_rad, "... or this much turning", 0.0, M_PI);
  g.local_translation_weight = num("local_translation_weight", g.local_translation_weight,
                                   "weight of a node's position in its own submaps", 0.0, 1e12);
  g.local_rotation_weight =
      num("local_rotation_weight", g.local_rotation_weight, "weight of a node's heading in its own submaps", 0.0, 1e12);
  g.consecutive_translation_weight = num("consecutive_translation_weight", g.consecutive_translation_weight,
                                         "weight of consecutive nodes' relative position", 0.0, 1e12);
  g.consecutive_rotation_weight = num("consecutive_rotation_weight", g.consecutive_rotation_weight,
                                      "weight of consecutive nodes' relative heading", 0.0, 1e12);
  g.loop_translation_weight =
      num("loop_translation_weight", g.loop_translation_weight, "weight of a loop closure's position", 0.0, 1e12);
  g.loop_rotation_weight =
      num("loop_rotation_weight", g.loop_rotation_weight, "weight of a loop closure's heading", 0.0, 1e12);
  g.odometry_translation_weight =
      num("odometry_translation_weight", g.odometry_translation_weight,
          "weight of consecutive nodes' relative position by odometry (0: none)", 0.0, 1e12);
  g.odometry_rotation_weight = num("odometry_rotation_weight", g.odometry_rotation_weight,
                                   "weight of consecutive nodes' relative heading by odometry (0: none)", 0.0, 1e12);
  window("loop_window", &g.loop_window, "loop closure:", 100.0);
  g.loop_window.min_angular_step_rad =
      num("loop_angular_step_rad", g.loop_window.min_angular_step_rad,
          "loop closure: the finest angular step (0: one cell at the farthest point)", 0.0, 1.0);
  g.loop_min_score = num("loop_min_score", g.loop_min_score, "a loop closure needs this match score (0..1)", 0.0, 1.0);
  g.loop_max_distance_m = num("loop_max_distance_m", g.loop_max_distance_m,
                              "search submaps whose origin lies this close to the node", 0.0, 1e6);
  g.loop_drift_m_per_m = num("loop_drift_m_per_m", g.loop_drift_m_per_m,
                             "loop search: the local window grows by this per metre of path between the submap and "
                             "the node, up to loop_window_m (0: loop_window_m alone)",
                             0.0, 10.0);
  g.loop_drift_rad_per_m = num("loop_drift_rad_per_m", g.loop_drift_rad_per_m,
                               "loop search: the local window's heading grows by this per metre of path, up to "
                               "loop_window_rad (0: loop_window_rad alone)",
                               0.0, 10.0);
  g.loop_verify_tolerance_m = num("loop_verify_tolerance_m", g.loop_verify_tolerance_m,
                                  "a closure is dropped when the neighbouring submap finds the node farther than this "
                                  "from where the closure puts it (0: no verification)",
                                  0.0, 10.0);
  window("loop_verify_window", &g.loop_verify_window, "verification: the neighbour's", 10.0);
  g.loop_every_nodes =
      count("loop_every_nodes", g.loop_every_nodes, "search loop closures for every k-th node", 1, 100000);
  g.loop_levels = count("loop_levels", g.loop_levels, "branch-and-bound levels of a finished submap", 1, 12);
  g.graph.huber_scale =
      num("huber_scale", g.graph.huber_scale,
          "loop closures with a weighted residual beyond this are down-weighted (and reported)", 1e-6, 1e9);
  g.graph.max_iterations = count("iterations", g.graph.max_iterations, "Ceres iterations per solve", 1, 10000);
  g.final_iterations = count("final_iterations", g.final_iterations, "Ceres iterations of the last solve", 1, 100000);
  g.optimize_every_nodes =
      count("optimize_every_nodes", g.optimize_every_nodes, "solve the graph after this many new nodes", 1, 1000000);
  g.background = s.GetBool("graph_background", g.background,
                           "solve on a worker thread while scans go on (false: in line, deterministic)");
  g.rerender_map = s.GetBool("graph_rerender_map", g.rerender_map,
                             "re-render the published map from the optimised poses after each solve");
  return g;
}

SlamOptions ParseSlamOptions(config::Section& s) {
  SlamOptions m;
  m.mode = s.GetEnum("mode", SlamMode::kFullSlam,
                     {{"full_slam", SlamMode::kFullSlam},
                      {"localization", SlamMode::kLocalization},
                      {"mapping_only", SlamMode::kMappingOnly},
                      {"action_only", SlamMode::kActionOnly},
                      {"graph_slam", SlamMode::kGraphSlam}},
                     "what runs: full SLAM (particle filter), localization on a known map, mapping from known poses, "
                     "particles driven by odometry alone, or graph SLAM (scan matching, pose graph, loop closure)");
  m.mapper = ParseMapperOptions(s);
  m.action = ParseActionModelOptions(s);
  m.sensor = ParseSensorModelOptions(s);
  m.filter = ParseParticleFilterOptions(s, m.mode);
  if (m.mode == SlamMode::kFullSlam || s.describing()) {  // the gate's keys exist where it works
    m.gate_fit_ratio = s.GetDouble("gate_fit_ratio", m.gate_fit_ratio,
                                   "full SLAM: a scan fitting the map at under this share of the recent mapped "
                                   "scans' median fit (corrupt, misplaced) is not mapped (0: off)",
                                   0.0, 1.0);
    m.gate_max_scans =
        static_cast<int>(s.GetInt("gate_max_scans", m.gate_max_scans,
                                  "... at most this many in a row: the next is mapped whatever it fits", 0, 1000));
  }
  if (m.mode == SlamMode::kFullSlam || s.describing()) {
    m.refine_estimate = s.GetBool("refine_estimate", m.refine_estimate,
                                  "full SLAM: fit each filter estimate to the hits the map holds (normal-distributions "
                                  "transform, between cells) and move the particles by the correction");
    // Read whether it is on or off: switching it off must not make the tuning keys unknown.
    m.refine.translation_weight = s.GetDouble("refine_translation_weight", m.refine.translation_weight,
                                              "refine_estimate: pull towards the filter's position [1/m]", 0.0, 1e9);
    m.refine.rotation_weight = s.GetDouble("refine_rotation_weight", m.refine.rotation_weight,
                                           "refine_estimate: pull towards the filter's heading [1/rad]", 0.0, 1e9);
    m.refine.min_sigma_m = s.GetDouble("refine_min_sigma_m", m.refine.min_sigma_m,
                                       "refine_estimate: added to each cell block's spread of hits", 1e-4, 1.0);
    m.refine.range_power = s.GetDouble("refine_range_power", m.refine.range_power,
                                       "refine_estimate: each hit weighs (its range / 1 m)^this in the blocks "
                                       "(0: alike; near hits taken scan after scan make the map follow the last poses)",
                                       0.0, 4.0);
  }
  // The graph keys exist in graph_slam mode only (elsewhere they are unknown keys); --list-stages
  // documents them too.
  if (m.mode == SlamMode::kGraphSlam || s.describing()) m.graph = ParseGraphSlamOptions(s);
  return m;
}

}  // namespace mbot::mapping
