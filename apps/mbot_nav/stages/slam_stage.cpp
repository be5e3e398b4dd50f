// `slam`: the adapter between the event stream and mapping::Slam (libs/mapping) — log-odds mapping,
// Monte-Carlo localization and full SLAM, in the mode the configuration picks — on a replayed log,
// the simulator or a live robot. It picks the channels, places each message at its time, deskews
// every scan with the odometry (mapping::TimeBeams, DeskewScan), hands it to Slam and emits the pose,
// SLAM's status, the particles and the map to the later stages; at the end slam_outputs.cpp writes
// the map, the trajectories and metrics.json.
#include <chrono>
#include <filesystem>
#include <cmath>
#include <optional>

#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/common/process.hpp"
#include "mbot/drivers/map_io.hpp"
#include "mbot/mapping/moving_scan.hpp"
#include "mbot/mapping/slam.hpp"
#include "report.hpp"
#include "slam_config.hpp"
#include "slam_inputs.hpp"
#include "slam_outputs.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

using drivers::EventKind;
using motion::Pose2D;
using motion::TimedPose;

class SlamStage : public Stage {
 public:
  explicit SlamStage(SlamStageOptions o)
      : options_(std::move(o)), slam_(options_.slam, 0), events_(options_.slam.filter.lost_inlier_fraction) {}

  void Start(const RunContext& ctx) override {
    bus_ = ctx.bus;
    slam_ = mapping::Slam(options_.slam, ctx.seed);
    inputs_.emplace(options_, ctx.seed);
    if (!options_.map_file.empty()) {
      std::string format;
      slam_.SetMap(drivers::ReadAnyMap(options_.map_file, &format));
      mbot::log::Info("slam: known map " + options_.map_file + " (" + format + ", " +
                      std::to_string(slam_.map().width()) + "x" + std::to_string(slam_.map().height()) + ")");
    }
    consistency_model_ = mapping::SensorModel(options_.slam.sensor);
    wall_start_ = std::chrono::steady_clock::now();
    if (!options_.resume_from.empty()) {
      mbot::log::Info("slam: resuming from checkpoint " + options_.resume_from + " at (" +
                      std::to_string(options_.initial_pose.x) + ", " + std::to_string(options_.initial_pose.y) + ")");
    }
    if (options_.checkpoint_every_s > 0) {
      checkpoint_path_ = (std::filesystem::path(ctx.output_dir) / options_.checkpoint_file).string();
    }
  }

  void OnEvent(const drivers::Event& in) override {
    if (inputs_->Add(in)) ProcessReadyScans(false);
  }

  void Finish(const RunContext& ctx, bool interrupted) override {
    ProcessReadyScans(true);
    if (slam_.graph()) {
      // Graph SLAM's poses are final only once the last loops are closed and the graph is solved.
      slam_.Finish();
      const std::vector<Pose2D> poses = slam_.Trajectory();
      for (size_t i = 0; i < records_.size() && i < poses.size(); ++i) records_[i].slam = poses[i];
    }
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start_).count();
    if (records_.empty()) {
      mbot::log::Warn("slam: no scan was processed (lidar channel '" + inputs_->lidar_channel() + "', " +
                      std::to_string(skipped_scans_) + " scans without poses); no outputs written");
      return;
    }
    WriteSlamOutputs(ctx, interrupted,
                     SlamRun{&options_, &slam_, &records_, &inputs_->ground_truth(), &inputs_->reference(), &events_,
                             &scan_sample_.items(), &particle_snapshots_, inputs_->first_t_us(), inputs_->last_t_us(),
                             inputs_->kidnapped_at_us(), skipped_scans_, wall_s});
  }

 private:
  void ProcessReadyScans(bool at_end) {
    while (const SlamInputs::Scan* p = inputs_->ReadyScan(at_end)) {
      ProcessScan(*p, p->t_us + options_.lidar_time_offset_us, inputs_->poses());
      inputs_->PopScan();
    }
  }

  void ProcessScan(const SlamInputs::Scan& p, int64_t t_end, const std::vector<TimedPose>& poses) {
    const drivers::LidarScan& scan = p.scan;
    // When was each beam measured, as a fraction of the scan's duration?
    const mapping::BeamTimes beams = mapping::TimeBeams(options_.beam_timing, scan.angles_rad, scan.beam_times_us,
                                                        p.previous_us >= 0 ? p.t_us - p.previous_us : 0);
    if (beams.beam_times_unusable) {
      mbot::log::WarnOnce("slam:beam_times",
                          "slam: beam_timing = beams, but this scan's beam times do not span the scan");
    }
    const std::vector<float>& fractions = beams.fractions;
    const int64_t duration = beams.duration_us;
    const int64_t max_gap = static_cast<int64_t>(options_.max_pose_gap_s * 1e6);
    Pose2D end_pose, start_pose;
    if (!motion::InterpolateAt(poses, t_end, max_gap, &end_pose) ||
        !motion::InterpolateAt(poses, t_end - duration, max_gap, &start_pose)) {
      ++skipped_scans_;
      return;
    }
    const Pose2D sensor = options_.lidar_pose_from_scan ? scan.sensor_pose : options_.lidar_pose;
    const auto wall0 = std::chrono::steady_clock::now();
    const std::vector<mapping::ScanRay> rays =
        mapping::DeskewScan(scan.ranges_m, scan.angles_rad, fractions, end_pose.Inverse().Compose(start_pose), sensor,
                            scan.max_range_m, options_.scan);
    if (!slam_.initialized() && !Initialize(t_end, end_pose)) {
      ++skipped_scans_;
      return;
    }
    const bool mapping_only = options_.slam.mode == mapping::SlamMode::kMappingOnly;
    const mapping::SlamStep step = slam_.ProcessScan(rays, end_pose, mapping_only ? &end_pose : nullptr);
    if (scan_sample_.Wants(records_.size())) scan_sample_.Add(records_.size(), consistency_model_.Prepare(rays));
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall0).count();

    ScanRecord r;
    r.t_us = t_end;
    r.stamp_us = p.stamp_us + options_.lidar_time_offset_us;
    r.slam = step.pose;
    r.updated = step.filter_updated;
    r.status = step.status;
    r.update_ms = ms;
    r.latency_us = p.latency_us;
    if (records_.size() % 64 == 0) rss_mb_ = ResidentMemoryMb();
    r.rss_mb = rss_mb_;
    Pose2D odo;
    r.odometry = motion::InterpolateAt(inputs_->odometry(), t_end, max_gap, &odo) ? odo : end_pose;
    records_.push_back(r);
    Publish(r);
    if (options_.particles_every > 0 && !mapping_only && !slam_.graph() &&
        records_.size() % options_.particles_every == 1) {
      for (const mapping::Particle& q : slam_.filter().particles()) particle_snapshots_.push_back(q.pose);
    }
    TrackEvents(r);
    MaybeCheckpoint(r);
    PairRecordsAndTrim(&*inputs_, &records_, &paired_, t_end - duration, max_gap);
  }

  // The map and pose, every checkpoint_every_s of the stream's time, for a run that has to resume.
  void MaybeCheckpoint(const ScanRecord& r) {
    if (checkpoint_path_.empty()) return;
    if (last_checkpoint_us_ >= 0 && r.t_us - last_checkpoint_us_ < options_.checkpoint_every_s * 1e6) return;
    last_checkpoint_us_ = r.t_us;
    try {
      drivers::WriteSlamCheckpoint(
          checkpoint_path_, slam_.map(),
          {"", r.slam, r.odometry, (r.t_us - inputs_->first_t_us()) * 1e-6, static_cast<long long>(records_.size())});
    } catch (const std::exception& e) {
      mbot::log::WarnOnce("slam:checkpoint", std::string("slam: cannot write the checkpoint: ") + e.what());
    }
  }

  // The estimate goes to the later stages (planner, explorer, controller) and the sink: the pose at
  // the scan's time every scan, the map every publish_map_every scans (and the first).
  void Publish(const ScanRecord& r) {
    if (!bus_) return;
    bus_->Emit(this, drivers::Event{r.t_us, r.t_us, "SLAM_POSE", EventKind::kPoseEstimate, r.slam});
    const bool builds_map = options_.slam.mode != mapping::SlamMode::kLocalization;
    // What the pose is worth, on change: a global search that has not settled gives no usable pose.
    const mapping::SlamState state = mapping::StateOf(options_.slam.mode, r.status);
    if (state != published_state_) {
      published_state_ = state;
      bus_->Emit(this, drivers::Event{r.t_us, r.t_us, "SLAM_STATUS", EventKind::kSlamStatus,
                                      mapping::SlamStatus{state, options_.slam.mode, r.status.spread_m}});
    }
    if (options_.publish_particles_every > 0 && !slam_.graph() &&
        records_.size() % options_.publish_particles_every == 0) {
      drivers::Particles p;
      for (const mapping::Particle& q : slam_.filter().particles())
        p.poses.push_back(q.pose), p.weights.push_back(q.weight);
      bus_->Emit(this, drivers::Event{r.t_us, r.t_us, "SLAM_PARTICLES", EventKind::kParticles, std::move(p)});
    }
    if (options_.publish_map_every > 0 &&
        (records_.size() == 1 || (builds_map && records_.size() % options_.publish_map_every == 0))) {
      bus_->Emit(this, drivers::Event{r.t_us, r.t_us, "SLAM_MAP", EventKind::kMap,
                                      std::make_shared<const mapping::OccupancyGrid>(slam_.map())});
    }
  }

  bool Initialize(int64_t t_us, const Pose2D& odometry) {
    const int64_t max_gap = static_cast<int64_t>(options_.max_pose_gap_s * 1e6);
    Pose2D start = options_.initial_pose;
    if (options_.initial == "global") {
      slam_.InitializeGlobal(odometry);
      events_.GlobalStarted();
      mbot::log::Info("slam: global localization with " + std::to_string(slam_.filter().particles().size()) +
                      " particles over the map's free space");
      return true;
    }
    if (options_.initial == "ground_truth" || options_.initial == "reference") {
      const auto& series = options_.initial == "ground_truth" ? inputs_->ground_truth() : inputs_->reference();
      if (!motion::InterpolateAt(series, t_us, max_gap, &start)) {
        // The series may not have reached this scan yet: take its latest pose if it is recent.
        if (series.empty() || std::llabs(series.back().t_us - t_us) > max_gap) return false;
        start = series.back().pose;
      }
    } else if (options_.initial == "odometry") {
      start = odometry;
    } else if (options_.resume_odometry) {
      // Resuming: the robot may have moved since the checkpoint; its odometry says how far, unless
      // it restarted too (then its odometry is in a new frame and the checkpoint's pose is the guess).
      const Pose2D moved = options_.resume_odometry->Inverse().Compose(odometry);
      if (std::hypot(moved.x, moved.y) < 2.0) start = start.Compose(moved);
    }
    slam_.Initialize(start, odometry, options_.initial_sigma_xy, options_.initial_sigma_theta);
    return true;
  }

  // Global-localization convergence and kidnapping: when lost was flagged, when the filter recovered.
  void TrackEvents(const ScanRecord& r) {
    const std::string said = events_.Add((r.t_us - inputs_->first_t_us()) * 1e-6, static_cast<int>(records_.size()) - 1,
                                         r.updated, r.status);
    if (!said.empty()) mbot::log::Info("slam: " + said);
  }

  SlamStageOptions options_;
  mapping::Slam slam_;
  mapping::SlamEventTracker events_;
  double rss_mb_ = 0;
  RecordPairing paired_;
  std::string checkpoint_path_;  // empty: no checkpoints
  int64_t last_checkpoint_us_ = -1;
  std::optional<SlamInputs> inputs_;
  Bus* bus_ = nullptr;
  std::optional<mapping::SlamState> published_state_;
  int skipped_scans_ = 0;
  std::vector<ScanRecord> records_;
  mapping::SensorModel consistency_model_{mapping::SensorModelOptions{}};
  ScanSample scan_sample_{2048};  // the map-consistency metric's scans: bounded for any run length
  std::vector<Pose2D> particle_snapshots_;
  std::chrono::steady_clock::time_point wall_start_;
};

}  // namespace

StageType SlamStageType() {
  return {"slam",
          "log-odds mapping, Monte-Carlo localization, full SLAM and graph SLAM (mode = full_slam | "
          "localization | mapping_only | action_only | graph_slam); writes the map, TUM trajectories and metrics.json",
          [](config::Section& s) -> std::unique_ptr<Stage> {
            return std::make_unique<SlamStage>(ParseSlamStageOptions(s));
          }};
}

}  // namespace mbot::app
