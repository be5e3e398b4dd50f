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

std::string TumHeader(const std::string& what) { return "# " + what + ": t x y z qx qy qz qw\n"; }

}  // namespace

SlamRecordWriter::SlamRecordWriter(const std::string& dir, const SlamStageOptions& options)
    : o_(options),
      dir_(dir + "/"),
      truth_name_(options.truth_is_reference ? "reference" : "ground truth"),
      spool_path_(TempPathFor(dir_ + "slam_records.spool")) {
  // What a run killed in this folder left (a SIGKILL renames nothing): gone before this one starts.
  for (const char* name : {"slam.tum", "odometry.tum", "ground_truth.tum", "slam_scans.csv"})
    RemoveStaleTempFiles(dir_ + name);
  slam_tum_ = std::make_unique<AtomicFileWriter>(dir_ + "slam.tum");
  slam_tum_->stream() << TumHeader(std::string("SLAM (") + mapping::ToString(options.session.slam.mode) + ")");
  odometry_tum_ = std::make_unique<AtomicFileWriter>(dir_ + "odometry.tum");
  odometry_tum_->stream() << TumHeader("odometry at the scan times");
  scans_csv_ = std::make_unique<AtomicFileWriter>(dir_ + "slam_scans.csv");
  scans_csv_->stream() << "t_s,x,y,theta,filter_updated,particles,ess,spread_m,inlier_fraction,fit_ratio,injected,"
                          "lost,converged,update_ms,rss_mb\n";
  spool_.open(spool_path_, std::ios::binary | std::ios::trunc | std::ios::in | std::ios::out);
  if (!spool_) throw std::runtime_error(spool_path_ + ": cannot create the slam stage's record spool");
  std::remove(spool_path_.c_str());  // the open stream keeps it; no name is left to clean up
}

SlamRecordWriter::~SlamRecordWriter() = default;

void SlamRecordWriter::Add(const ScanRecord& r, int64_t first_t_us) {
  Spooled sp;
  std::memset(static_cast<void*>(&sp), 0, sizeof sp);  // the padding too: the bytes go to disk
  sp.t_us = r.t_us;
  sp.tum_t_us = o_.tum_stamps ? r.stamp_us : r.t_us;
  sp.latency_us = r.latency_us;
  sp.slam = r.slam;
  sp.odometry = r.odometry;
  sp.updated = r.updated;
  sp.update_ms = static_cast<float>(r.update_ms);
  sp.ess = static_cast<float>(r.status.ess);
  slam_tum_->stream() << TumLine(sp.tum_t_us * 1e-6, r.slam.x, r.slam.y, r.slam.theta);
  odometry_tum_->stream() << TumLine(sp.tum_t_us * 1e-6, r.odometry.x, r.odometry.y, r.odometry.theta);
  char line[256];
  std::snprintf(line, sizeof line, "%.6f,%.4f,%.4f,%.5f,%d,%d,%.1f,%.4f,%.3f,%.3f,%d,%d,%d,%.3f,%.1f\n", r.t_us * 1e-6,
                r.slam.x, r.slam.y, r.slam.theta, r.updated, r.status.particles, r.status.ess, r.status.spread_m,
                r.status.inlier_fraction, r.status.fit_ratio, r.status.injected, r.status.lost, r.status.converged,
                r.update_ms, r.rss_mb);
  scans_csv_->stream() << line;
  // Each scan's pose against the truth at its time: within the scoring window and not too late.
  const std::optional<Pose2D>& truth = o_.truth_is_reference ? r.reference : r.truth;
  if (truth) {
    sp.has_truth = 1;
    sp.truth = *truth;
    if (!truth_tum_) {
      truth_tum_ = std::make_unique<AtomicFileWriter>(dir_ + "ground_truth.tum");
      truth_tum_->stream() << TumHeader(truth_name_ + " at the scan times");
    }
    truth_tum_->stream() << TumLine(sp.tum_t_us * 1e-6, truth->x, truth->y, truth->theta);
    const bool late = o_.score_max_latency_us > 0 && r.latency_us > o_.score_max_latency_us;
    unscored_late_ += late;
    sp.scored = r.t_us >= o_.score_from_us + first_t_us && !late;
    if (sp.scored && !o_.truth_is_reference && r.reference) sp.has_reference = 1, sp.reference = *r.reference;
  }
  spool_.write(reinterpret_cast<const char*>(&sp), sizeof sp);
  if (!spool_) throw std::runtime_error(spool_path_ + ": write failed (disk full?)");
  ++records_;
}

void SlamRecordWriter::Commit() {
  spool_.flush();
  if (!spool_) throw std::runtime_error(spool_path_ + ": write failed (disk full?)");
  slam_tum_->Commit();
  odometry_tum_->Commit();
  scans_csv_->Commit();
  if (truth_tum_) truth_tum_->Commit();
}

void SlamRecordWriter::ForEach(const std::function<void(const Spooled&)>& f) {
  spool_.flush();
  spool_.clear();
  spool_.seekg(0);
  Spooled sp;
  size_t n = 0;
  while (n < records_ && spool_.read(reinterpret_cast<char*>(&sp), sizeof sp)) f(sp), ++n;
  spool_.clear();
  spool_.seekp(0, std::ios::end);
  if (n != records_) {
    throw std::runtime_error(spool_path_ + ": read back " + std::to_string(n) + " of " + std::to_string(records_) +
                             " records");
  }
}

void WriteSlamOutputs(const RunContext& ctx, bool interrupted, const SlamStageOptions& options,
                      const mapping::SlamSession& session, SlamRecordWriter& records, double wall_s) {
  records.Commit();
  const mapping::SlamInputs& inputs = session.inputs();
  const std::vector<mapping::ScanSample::Item>& scan_points = session.scan_points();
  const int64_t first_t_us = inputs.first_t_us(), last_t_us = inputs.last_t_us();
  const std::string dir = ctx.output_dir + "/";
  const std::string truth_name = options.truth_is_reference ? "reference" : "ground truth";
  using Spooled = SlamRecordWriter::Spooled;
  using motion::AteAccumulator;
  using motion::AteAlignment;

  // The scores, read back from the spool in two passes: the alignments, then the errors.
  struct Scored {
    std::vector<AteAccumulator> slam, odometry, reference;  // aligned, anchored, unaligned
  } acc;
  for (auto* v : {&acc.slam, &acc.odometry, &acc.reference})
    for (AteAlignment a : {AteAlignment::kBestFitSE2, AteAlignment::kFirstPose, AteAlignment::kNone})
      v->emplace_back(a);
  std::vector<Pose2D> slam_path, odometry_path, truth_path;  // the PNG's (read back, freed at the end)
  std::vector<double> update_ms, filter_ms, ess;
  std::vector<motion::TimedPose> relation_path;
  int updates = 0;
  records.ForEach([&](const Spooled& r) {
    slam_path.push_back(r.slam);
    odometry_path.push_back(r.odometry);
    if (r.has_truth) truth_path.push_back(r.truth);
    update_ms.push_back(r.update_ms);
    if (r.updated) ++updates, filter_ms.push_back(r.update_ms), ess.push_back(r.ess);
    if (!options.relations_file.empty()) relation_path.push_back({r.tum_t_us, r.slam});
    if (!r.scored) return;
    for (int k = 0; k < 3; ++k) {
      acc.slam[k].AddForAlignment(r.slam, r.truth);
      acc.odometry[k].AddForAlignment(r.odometry, r.truth);
      if (r.has_reference) acc.reference[k].AddForAlignment(r.reference, r.truth);
    }
  });
  records.ForEach([&](const Spooled& r) {
    if (!r.scored) return;
    for (int k = 0; k < 3; ++k) {
      acc.slam[k].AddError(r.slam, r.truth);
      acc.odometry[k].AddError(r.odometry, r.truth);
      if (r.has_reference) acc.reference[k].AddError(r.reference, r.truth);
    }
  });
  auto errors = [](const std::vector<AteAccumulator>& a) {
    return motion::TrajectoryErrors{a[0].Result(), a[1].Result(), a[2].Result()};
  };

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
  if (!truth_path.empty()) overlays.push_back({std::move(truth_path), 0, 170, 0, false, truth_name});
  overlays.push_back({std::move(odometry_path), 220, 0, 0, false, "odometry"});
  overlays.push_back({std::move(slam_path), 0, 60, 255, false, "SLAM"});
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
  j["filter_updates"] = updates;
  j["particles"] = options.session.slam.filter.particles;
  const bool any_truth =
      records.has_truth() || !(options.truth_is_reference ? inputs.reference() : inputs.ground_truth()).empty();
  j["truth"] = any_truth ? truth_name : "none";
  j["scans_not_scored_late"] = records.unscored_late();
  if (acc.slam[0].samples() > 0) {
    const motion::TrajectoryErrors slam_errors = errors(acc.slam);
    const motion::TrajectoryErrors odo_errors = errors(acc.odometry);
    j["slam_ate"] = reports::TrajectoryErrorsJson(slam_errors);
    j["odometry_ate"] = reports::TrajectoryErrorsJson(odo_errors);
    if (acc.reference[0].samples() > 0) j["reference_ate"] = reports::TrajectoryErrorsJson(errors(acc.reference));
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
    j["relations"] = RelationsJson(options.relations_file, relation_path, &relations_error);
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
  mbot::log::Info("slam: " + std::to_string(records.records()) + " scans (" + std::to_string(updates) +
                  " filter updates), scan consistency " + Num(consistency, 3) + ", median " +
                  Num(reports::SampleStats::Of(update_ms).median, 3) + " ms per scan; outputs in " + ctx.output_dir);
  if (!relations_error.empty()) throw motion::RelationsError(relations_error);
}

}  // namespace mbot::app
