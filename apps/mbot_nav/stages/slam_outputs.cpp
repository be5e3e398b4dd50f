#include "slam_outputs.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
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

}  // namespace

void WriteSlamOutputs(const RunContext& ctx, bool interrupted, const SlamStageOptions& options,
                      const mapping::SlamSession& session, mapping::SlamRecordWriter& records, double wall_s) {
  records.Commit();
  const mapping::SlamInputs& inputs = session.inputs();
  const std::vector<mapping::ScanSample::Item>& scan_points = session.scan_points();
  const int64_t first_t_us = inputs.first_t_us(), last_t_us = inputs.last_t_us();
  const std::string dir = ctx.output_dir + "/";
  const std::string truth_name = options.truth_is_reference ? "reference" : "ground truth";
  // The scores and the paths, read back from the spool.
  mapping::SlamRecordSummary summary = records.ReadBack(!options.relations_file.empty());
  const std::vector<double>& update_ms = summary.update_ms;
  const int updates = summary.updates;

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
  if (!summary.truth_path.empty()) overlays.push_back({std::move(summary.truth_path), 0, 170, 0, false, truth_name});
  overlays.push_back({std::move(summary.odometry_path), 220, 0, 0, false, "odometry"});
  overlays.push_back({std::move(summary.slam_path), 0, 60, 255, false, "SLAM"});
  drivers::WriteMapPngWithOverlays(map, overlays, options.png_scale, base + ".png");
  overlays.clear();

  // Map sharpness: the share of every scan's returns that end within inlier_distance_m of an
  // obstacle of the final map, at the pose the scan was given (blurred or doubled walls lower it).
  double consistency = NAN;
  if (!scan_points.empty()) {
    mapping::SensorModel model(options.session.slam.sensor);
    model.SetMap(map);
    double sum = 0;
    for (size_t i = 0; i < scan_points.size(); ++i)
      sum += model.InlierFraction(scan_points[i].value.pose, scan_points[i].value.points);
    consistency = sum / scan_points.size();
  }
  const double data_s = (last_t_us - first_t_us) * 1e-6;
  reports::Json j;
  j["mode"] = mapping::ToString(options.session.slam.mode);
  j["seed"] = ctx.seed;
  j["interrupted"] = interrupted;
  j["source"] = ctx.source_path;
  j["scans"] = records.records();
  j["scans_skipped"] = session.skipped_scans();
  j["scans_gated"] = session.slam().scans_gated();
  if (options.session.scan_perturbation.any()) {
    j["injected"]["glass_beams"] = session.scan_perturbation().glass_beams();
    j["injected"]["person_beams"] = session.scan_perturbation().person_beams();
  }
  j["filter_updates"] = updates;
  j["particles"] = options.session.slam.filter.particles;
  const bool any_truth =
      records.has_truth() || !(options.truth_is_reference ? inputs.reference() : inputs.ground_truth()).empty();
  j["truth"] = any_truth ? truth_name : "none";
  j["scans_not_scored_late"] = records.unscored_late();
  if (summary.slam) {
    const motion::TrajectoryErrors& slam_errors = *summary.slam;
    const motion::TrajectoryErrors& odo_errors = *summary.odometry;
    j["slam_ate"] = reports::TrajectoryErrorsJson(slam_errors);
    j["odometry_ate"] = reports::TrajectoryErrorsJson(odo_errors);
    if (summary.reference) j["reference_ate"] = reports::TrajectoryErrorsJson(*summary.reference);
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
    j["relations"] = RelationsJson(options.relations_file, summary.relation_path, &relations_error);
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
  j["effective_sample_size"] = reports::SampleStats::Of(summary.ess).ToJson();
  j["timing"] = {{"scan_update_ms", reports::SampleStats::Of(update_ms).ToJson()},
                 {"filter_update_ms", reports::SampleStats::Of(summary.filter_ms).ToJson()},
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
  mbot::log::Info("slam: " + std::to_string(records.records()) + " scans (" + std::to_string(updates) +
                  " filter updates), scan consistency " + Num(consistency, 3) + ", median " +
                  Num(reports::SampleStats::Of(update_ms).median, 3) + " ms per scan; outputs in " + ctx.output_dir);
  if (!relations_error.empty()) throw motion::RelationsError(relations_error);
}

}  // namespace mbot::app
