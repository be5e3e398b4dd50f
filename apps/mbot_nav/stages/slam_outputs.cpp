#include "slam_outputs.hpp"

#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/log.hpp"
#include "mbot/drivers/map_io.hpp"
#include "mbot/mapping/pose_graph_io.hpp"
#include "mbot/motion/trajectory_error.hpp"
#include "report.hpp"
#include "slam_graph_report.hpp"

namespace mbot::app {
namespace {

using mapping::ScanRecord;
using motion::Pose2D;
using motion::TimedPose;

std::vector<Pose2D> PosesOf(const std::vector<TimedPose>& s) {
  std::vector<Pose2D> v;
  for (const TimedPose& p : s) v.push_back(p.pose);
  return v;
}

void WriteScansCsv(const std::string& path, const std::vector<ScanRecord>& records) {
  WriteFileAtomically(path, [&](std::ostream& o) {
    o << "t_s,x,y,theta,filter_updated,particles,ess,spread_m,inlier_fraction,fit_ratio,injected,lost,converged,update_"
         "ms,rss_mb\n";
    char line[256];
    for (const ScanRecord& r : records) {
      std::snprintf(line, sizeof line, "%.6f,%.4f,%.4f,%.5f,%d,%d,%.1f,%.4f,%.3f,%.3f,%d,%d,%d,%.3f,%.1f\n",
                    r.t_us * 1e-6, r.slam.x, r.slam.y, r.slam.theta, r.updated, r.status.particles, r.status.ess,
                    r.status.spread_m, r.status.inlier_fraction, r.status.fit_ratio, r.status.injected, r.status.lost,
                    r.status.converged, r.update_ms, r.rss_mb);
      o << line;
    }
  });
}

}  // namespace

void WriteSlamOutputs(const RunContext& ctx, bool interrupted, const SlamStageOptions& options,
                      const mapping::SlamSession& session, double wall_s) {
  const std::vector<ScanRecord>& records = session.records();
  const mapping::SlamInputs& inputs = session.inputs();
  const std::vector<TimedPose>& reference = inputs.reference();
  const std::vector<TimedPose>& ground_truth = inputs.ground_truth();
  const std::vector<mapping::ScanSample::Item>& scan_points = session.scan_points();
  const int64_t first_t_us = inputs.first_t_us(), last_t_us = inputs.last_t_us();
  const std::string dir = ctx.output_dir + "/";
  const int64_t max_gap = static_cast<int64_t>(options.session.max_pose_gap_s * 1e6);
  const std::vector<TimedPose>& truth_series = options.truth_is_reference ? reference : ground_truth;
  const std::string truth_name = options.truth_is_reference ? "reference" : "ground truth";

  // Each scan's pose against the truth at its time: within the scoring window and not too late.
  std::vector<TimedPose> slam_path, odometry_path, truth_path;
  int unscored_late = 0;
  std::vector<Pose2D> est_paired, odo_paired, truth_paired, ref_paired, ref_truth_paired;
  for (const ScanRecord& r : records) {
    const int64_t tum_t = options.tum_stamps ? r.stamp_us : r.t_us;
    slam_path.push_back({tum_t, r.slam});
    odometry_path.push_back({tum_t, r.odometry});
    Pose2D t;
    const std::optional<Pose2D>& kept = options.truth_is_reference ? r.reference : r.truth;
    if (kept) {
      t = *kept;
    } else if (!motion::InterpolateAt(truth_series, r.t_us, max_gap, &t)) {
      continue;
    }
    truth_path.push_back({tum_t, t});
    const bool late = options.score_max_latency_us > 0 && r.latency_us > options.score_max_latency_us;
    unscored_late += late;
    if (r.t_us < options.score_from_us + first_t_us || late) continue;
    est_paired.push_back(r.slam);
    odo_paired.push_back(r.odometry);
    truth_paired.push_back(t);
    Pose2D ref;
    if (!options.truth_is_reference &&
        (r.reference ? (ref = *r.reference, true) : motion::InterpolateAt(reference, r.t_us, max_gap, &ref))) {
      ref_paired.push_back(ref);
      ref_truth_paired.push_back(t);
    }
  }
  WriteTum(dir + "slam.tum", std::string("SLAM (") + mapping::ToString(options.session.slam.mode) + ")", slam_path);
  WriteTum(dir + "odometry.tum", "odometry at the scan times", odometry_path);
  WriteScansCsv(dir + "slam_scans.csv", records);
  if (!truth_path.empty()) WriteTum(dir + "ground_truth.tum", truth_name + " at the scan times", truth_path);

  const mapping::GraphSlam* graph = session.slam().graph();
  std::optional<mapping::OccupancyGrid> rendered;
  if (graph && options.map_resolution_m > 0) rendered = graph->RenderMap(options.map_resolution_m);
  const mapping::OccupancyGrid& map = rendered ? *rendered : session.slam().map();
  const std::string base = dir + options.map_basename;
  if (graph && !options.graph_file.empty()) mapping::WriteG2o(graph->Graph(), dir + options.graph_file);
  if (session.slam().BuildsMap()) {
    drivers::WriteBotlabMap(map, base + ".map");
    drivers::WriteRosMap(map, base + ".yaml");
    if (options.octomap_height_m > 0) drivers::WriteOctomap(map, options.octomap_height_m, base + ".bt");
  }
  std::vector<drivers::MapOverlay> overlays;
  if (!session.particle_snapshots().empty())
    overlays.push_back({session.particle_snapshots(), 255, 160, 0, true, "particles"});
  if (!truth_path.empty()) overlays.push_back({PosesOf(truth_path), 0, 170, 0, false, truth_name});
  overlays.push_back({PosesOf(odometry_path), 220, 0, 0, false, "odometry"});
  overlays.push_back({PosesOf(slam_path), 0, 60, 255, false, "SLAM"});
  drivers::WriteMapPngWithOverlays(map, overlays, options.png_scale, base + ".png");

  // Map sharpness: the share of every scan's returns that end within inlier_distance_m of an
  // obstacle of the final map, at the pose the scan was given (blurred or doubled walls lower it).
  double consistency = NAN;
  if (!scan_points.empty()) {
    mapping::SensorModel model(options.session.slam.sensor);
    model.SetMap(map);
    double sum = 0;
    for (size_t i = 0; i < scan_points.size(); ++i)
      sum += model.InlierFraction(records[scan_points[i].index].slam, scan_points[i].value);
    consistency = sum / scan_points.size();
  }
  std::vector<double> update_ms, filter_ms, ess;
  int updates = 0;
  for (const ScanRecord& r : records) {
    update_ms.push_back(r.update_ms);
    if (r.updated) ++updates, filter_ms.push_back(r.update_ms), ess.push_back(r.status.ess);
  }
  const double data_s = (last_t_us - first_t_us) * 1e-6;
  reports::Json j;
  j["mode"] = mapping::ToString(options.session.slam.mode);
  j["seed"] = ctx.seed;
  j["interrupted"] = interrupted;
  j["source"] = ctx.source_path;
  j["scans"] = records.size();
  j["scans_skipped"] = session.skipped_scans();
  j["filter_updates"] = updates;
  j["particles"] = options.session.slam.filter.particles;
  j["truth"] = truth_series.empty() ? "none" : truth_name;
  j["scans_not_scored_late"] = unscored_late;
  if (!est_paired.empty()) {
    const motion::TrajectoryErrors slam_errors = motion::EvaluateTrajectory(est_paired, truth_paired);
    const motion::TrajectoryErrors odo_errors = motion::EvaluateTrajectory(odo_paired, truth_paired);
    j["slam_ate"] = reports::TrajectoryErrorsJson(slam_errors);
    j["odometry_ate"] = reports::TrajectoryErrorsJson(odo_errors);
    if (!ref_paired.empty())
      j["reference_ate"] = reports::TrajectoryErrorsJson(motion::EvaluateTrajectory(ref_paired, ref_truth_paired));
    const motion::AteResult& a = slam_errors.aligned;
    const motion::AteResult& o = odo_errors.aligned;
    mbot::log::Info("slam: ATE vs " + truth_name + " (aligned, " + std::to_string(a.samples) + " scans): RMSE x " +
                    Num(a.x.rmse, 3) + " m, y " + Num(a.y.rmse, 3) + " m, xy " + Num(a.xy.rmse, 3) + " m, theta " +
                    Num(a.theta.rmse * 180 / M_PI, 3) + " deg; odometry xy " + Num(o.xy.rmse, 3) + " m, theta " +
                    Num(o.theta.rmse * 180 / M_PI, 3) + " deg");
  }
  if (graph) {
    j["graph"] = GraphSlamJson(graph->stats());
    if (!options.graph_file.empty()) j["graph"]["g2o"] = options.graph_file;
  }
  // A relations file that does not fit the run is an error, but only once everything else is written.
  std::string relations_error;
  if (!options.relations_file.empty())
    j["relations"] = RelationsJson(options.relations_file, slam_path, &relations_error);
  const mapping::SlamEventTracker& ev = session.events();
  j["global_localization"] = nullptr;
  if (ev.global()) {
    j["global_localization"] = {{"converged", ev.converged_at_s() >= 0},
                                {"converged_at_s", reports::Number(ev.converged_at_s())},
                                {"converged_at_scan", ev.converged_at_scan()}};
  }
  j["kidnapping"] = nullptr;
  if (inputs.kidnapped_at_us() >= 0) {
    j["kidnapping"] = {{"at_s", reports::Number((inputs.kidnapped_at_us() - first_t_us) * 1e-6)}};
  }
  reports::Json lost = reports::Json::array();
  for (const mapping::SlamEventTracker::Lost& l : ev.lost()) {
    const bool recovered = l.recovered_at_scan >= 0;
    lost.push_back(
        {{"at_s", reports::Number(l.at_s)},
         {"at_scan", l.at_scan},
         {"recovered_at_s", recovered ? reports::Number(l.recovered_at_s) : reports::Json(nullptr)},
         {"scans_to_recover", recovered ? reports::Json(l.recovered_at_scan - l.at_scan) : reports::Json(nullptr)}});
  }
  j["lost"] = std::move(lost);
  j["effective_sample_size"] = reports::SampleStats::Of(ess).ToJson();
  j["timing"] = {{"scan_update_ms", reports::SampleStats::Of(update_ms).ToJson()},
                 {"filter_update_ms", reports::SampleStats::Of(filter_ms).ToJson()},
                 {"wall_s", reports::Number(wall_s)},
                 {"data_s", reports::Number(data_s)},
                 {"real_time_factor", reports::Number(wall_s > 0 ? data_s / wall_s : NAN)}};
  j["map"] = {{"scan_consistency", reports::Number(consistency)},
              {"width", map.width()},
              {"height", map.height()},
              {"resolution", reports::Number(map.resolution())},
              {"origin_x", reports::Number(map.origin_x())},
              {"origin_y", reports::Number(map.origin_y())}};
  reports::WriteJson(dir + "metrics.json", j);
  mbot::log::Info("slam: " + std::to_string(records.size()) + " scans (" + std::to_string(updates) +
                  " filter updates), scan consistency " + Num(consistency, 3) + ", median " +
                  Num(reports::SampleStats::Of(update_ms).median, 3) + " ms per scan; outputs in " + ctx.output_dir);
  if (!relations_error.empty()) throw motion::RelationsError(relations_error);
}

}  // namespace mbot::app
