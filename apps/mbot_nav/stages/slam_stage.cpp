// `slam`: log-odds mapping, Monte-Carlo localization and full SLAM on the event stream (a replayed
// log, the simulator, a live robot), in the mode the configuration picks. Every scan is deskewed
// with odometry, handed to mbot::mapping::Slam, and its pose recorded; at the end the stage writes
// the map (.map, PGM + YAML, a PNG with the SLAM, odometry and ground-truth paths, an OctoMap), the
// trajectories in TUM format and metrics.json (ATE per axis, aligned and anchored, and timing).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <map>
#include <optional>
#include <random>
#include <sstream>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/common/strings.hpp"
#include "mbot/drivers/map_io.hpp"
#include "mbot/mapping/slam.hpp"
#include "mbot/motion/trajectory_error.hpp"
#include "mbot/motion/wheel_odometry.hpp"
#include "report.hpp"
#include "slam_config.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

using drivers::EventKind;
using motion::Pose2D;
using motion::TimedPose;

// One processed scan.
struct ScanRecord {
  int64_t t_us = 0;
  Pose2D slam, odometry;
  bool updated = false;
  mapping::FilterStatus status;
  double update_ms = 0;
  int64_t latency_us = 0;
};

class SlamStage : public Stage {
 public:
  explicit SlamStage(SlamStageOptions o)
      : options_(std::move(o)), slam_(options_.slam, 0), noise_rng_(0) {}

  void Start(const RunContext& ctx) override {
    bus_ = ctx.bus;
    slam_ = mapping::Slam(options_.slam, ctx.seed);
    noise_rng_.seed(ctx.seed ^ 0x6f646f6dULL);
    if (!options_.map_file.empty()) {
      std::string format;
      slam_.SetMap(drivers::ReadAnyMap(options_.map_file, &format));
      mbot::log::Info("slam: known map " + options_.map_file + " (" + format + ", " +
                      std::to_string(slam_.map().width()) + "x" + std::to_string(slam_.map().height()) + ")");
    }
    if (options_.encoder_odometry) wheel_odometry_.emplace(options_.wheels);
    consistency_model_ = mapping::SensorModel(options_.slam.sensor);
    wall_start_ = std::chrono::steady_clock::now();
  }

  void OnEvent(const drivers::Event& in) override {
    if (first_t_us_ < 0) first_t_us_ = in.t_us;
    last_t_us_ = in.t_us;
    drivers::Event retimed;
    const drivers::Event& ev = Retime(in, &retimed);
    switch (ev.kind) {
      case EventKind::kOdometry:
        if (!options_.encoder_odometry && Accept(&odometry_channel_, options_.odometry_channel, ev)) {
          AddOdometry(ev.t_us, std::get<Pose2D>(ev.payload));
        }
        break;
      case EventKind::kEncoders:
        if (options_.encoder_odometry && Accept(&encoder_channel_, "", ev)) {
          const auto& e = std::get<drivers::EncoderTicks>(ev.payload);
          AddOdometry(ev.t_us, wheel_odometry_->Update(e.left_ticks, e.right_ticks));
        }
        break;
      case EventKind::kGroundTruth:
        if (Accept(&truth_channel_, options_.ground_truth_channel, ev)) Append(&ground_truth_, ev);
        break;
      case EventKind::kReferencePose:
        if (Accept(&reference_channel_, options_.reference_channel, ev)) Append(&reference_, ev);
        break;
      case EventKind::kLidar:
        if (Accept(&lidar_channel_, options_.lidar_channel, ev)) {
          // How late the scan arrived: its stamp is the robot's clock, its event time the logger's.
          const int64_t latency = std::llabs(in.t_us - in.stamp_us) < 2'000'000 ? in.t_us - in.stamp_us : 0;
          pending_.push_back(Pending{ev.t_us, previous_scan_us_, latency, std::get<drivers::LidarScan>(ev.payload)});
          previous_scan_us_ = ev.t_us;
        }
        break;
      default:
        return;
    }
    ProcessReadyScans(false);
  }

  void Finish(const RunContext& ctx, bool interrupted) override {
    ProcessReadyScans(true);
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start_).count();
    if (records_.empty()) {
      mbot::log::Warn("slam: no scan was processed (lidar channel '" + lidar_channel_ + "', " +
                      std::to_string(skipped_scans_) + " scans without poses); no outputs written");
      return;
    }
    WriteOutputs(ctx, interrupted, wall_s);
  }

 private:
  struct Pending {
    int64_t t_us;
    int64_t previous_us;  // the scan before, or -1
    int64_t latency_us;   // arrival time − stamp when both share a clock, else 0
    drivers::LidarScan scan;
  };

  // The time each message is placed at: its own stamp when the channel's stamps share the log's
  // clock (the robot's measurement time, immune to network bursts), else its arrival time.
  const drivers::Event& Retime(const drivers::Event& ev, drivers::Event* copy) {
    if (options_.time_base == "event" || ev.stamp_us == 0) return ev;
    auto it = stamp_channels_.find(ev.channel);
    if (it == stamp_channels_.end()) {
      const bool same_clock = options_.time_base == "stamp" || std::llabs(ev.stamp_us - ev.t_us) < 2'000'000;
      it = stamp_channels_.emplace(ev.channel, same_clock).first;
      if (!same_clock) mbot::log::Info("slam: " + ev.channel + " stamps use another clock; using arrival times");
    }
    if (!it->second) return ev;
    if (ev.kind != EventKind::kLidar && ev.kind != EventKind::kOdometry && ev.kind != EventKind::kEncoders &&
        ev.kind != EventKind::kGroundTruth && ev.kind != EventKind::kReferencePose) {
      return ev;
    }
    *copy = ev;
    copy->t_us = ev.stamp_us;
    return *copy;
  }

  // Takes the first channel of a kind unless the options name one.
  bool Accept(std::string* chosen, const std::string& wanted, const drivers::Event& ev) {
    if (!wanted.empty()) return ev.channel == wanted;
    if (chosen->empty()) *chosen = ev.channel;
    if (*chosen == ev.channel) return true;
    mbot::log::WarnOnce("slam:" + ev.channel, "slam: " + std::string(drivers::ToString(ev.kind)) + " channel " +
                                                  ev.channel + " ignored; using " + *chosen);
    return false;
  }

  static void Append(std::vector<TimedPose>* series, const drivers::Event& ev) {
    if (!series->empty() && ev.t_us < series->back().t_us) return;
    series->push_back({ev.t_us, std::get<Pose2D>(ev.payload)});
  }

  // Odometry as the filter sees it: with the configured perturbations (noise, a kidnapping jump).
  void AddOdometry(int64_t t_us, const Pose2D& raw) {
    Pose2D out = raw;
    if (options_.noise_trans > 0 || options_.noise_rot > 0) {
      if (!odometry_.empty()) {
        const Pose2D d = last_raw_odometry_.Inverse().Compose(raw);
        const double ds = std::hypot(d.x, d.y);
        std::normal_distribution<double> n(0.0, 1.0);
        const Pose2D noisy{d.x + options_.noise_trans * ds * n(noise_rng_), d.y + options_.noise_trans * ds * n(noise_rng_),
                           d.theta + options_.noise_rot * (std::abs(d.theta) + ds) * n(noise_rng_)};
        out = noisy_odometry_.Compose(noisy);
      }
      noisy_odometry_ = out;
    }
    last_raw_odometry_ = raw;
    if (options_.kidnap_at_s >= 0 && first_t_us_ >= 0 && t_us - first_t_us_ >= options_.kidnap_at_s * 1e6) {
      if (kidnap_us_ < 0) kidnap_us_ = t_us;
      out = options_.kidnap_offset.Compose(out);
    }
    if (!odometry_.empty() && t_us < odometry_.back().t_us) return;
    odometry_.push_back({t_us, out});
  }

  const std::vector<TimedPose>& PoseSource() const {
    return options_.slam.mode == mapping::SlamMode::kMappingOnly
               ? (options_.mapping_poses_from_reference ? reference_ : ground_truth_)
               : odometry_;
  }

  void ProcessReadyScans(bool at_end) {
    const std::vector<TimedPose>& poses = PoseSource();
    while (!pending_.empty()) {
      Pending& p = pending_.front();
      const int64_t t_end = p.t_us + options_.lidar_time_offset_us;
      if (!at_end && (poses.empty() || poses.back().t_us < t_end)) return;  // wait for the poses to catch up
      ProcessScan(p, t_end, poses);
      pending_.pop_front();
    }
  }

  void ProcessScan(const Pending& p, int64_t t_end, const std::vector<TimedPose>& poses) {
    const drivers::LidarScan& scan = p.scan;
    const size_t n = scan.ranges_m.size();
    // When was each beam measured, as a fraction of the scan's duration?
    std::vector<float> fractions;
    int64_t duration = 0;
    const int64_t period = p.previous_us >= 0 ? p.t_us - p.previous_us : 0;
    const bool beams_usable = scan.beam_times_us.size() == n && n > 1 && period > 0 &&
                              scan.beam_times_us.back() - scan.beam_times_us.front() > period / 2;
    if (options_.beam_timing == "beams" || (options_.beam_timing == "auto" && beams_usable)) {
      if (!beams_usable) {
        mbot::log::WarnOnce("slam:beam_times", "slam: beam_timing = beams, but this scan's beam times do not span the scan");
      } else {
        duration = scan.beam_times_us.back() - scan.beam_times_us.front();
        fractions.resize(n);
        for (size_t i = 0; i < n; ++i) {
          fractions[i] = static_cast<float>(double(scan.beam_times_us[i] - scan.beam_times_us.front()) / duration);
        }
      }
    } else if (options_.beam_timing == "spread" ||
               (options_.beam_timing == "auto" && period > 0 && period < 1'000'000 && CoversTurn(scan))) {
      // A spinning lidar without usable per-beam times: beams evenly over the time since the last scan.
      duration = period > 0 && period < 1'000'000 ? period : 0;
      fractions.resize(n);
      for (size_t i = 0; i < n; ++i) fractions[i] = n > 1 ? float(double(i) / (n - 1)) : 1.0f;
    }
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
    if (scan_points_.size() < kMaxKeptScans) scan_points_.push_back(consistency_model_.Prepare(rays));
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall0).count();

    ScanRecord r;
    r.t_us = t_end;
    r.slam = step.pose;
    r.updated = step.filter_updated;
    r.status = step.status;
    r.update_ms = ms;
    r.latency_us = p.latency_us;
    Pose2D odo;
    r.odometry = motion::InterpolateAt(odometry_, t_end, max_gap, &odo) ? odo : end_pose;
    records_.push_back(r);
    Publish(r);
    if (options_.particles_every > 0 && !mapping_only && records_.size() % options_.particles_every == 1) {
      for (const mapping::Particle& q : slam_.filter().particles()) particle_snapshots_.push_back(q.pose);
    }
    TrackEvents(r);
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
    if (options_.publish_particles_every > 0 && records_.size() % options_.publish_particles_every == 0) {
      drivers::Particles p;
      for (const mapping::Particle& q : slam_.filter().particles()) p.poses.push_back(q.pose), p.weights.push_back(q.weight);
      bus_->Emit(this, drivers::Event{r.t_us, r.t_us, "SLAM_PARTICLES", EventKind::kParticles, std::move(p)});
    }
    if (options_.publish_map_every > 0 && (records_.size() == 1 || (builds_map && records_.size() % options_.publish_map_every == 0))) {
      bus_->Emit(this, drivers::Event{r.t_us, r.t_us, "SLAM_MAP", EventKind::kMap,
                                      std::make_shared<const mapping::OccupancyGrid>(slam_.map())});
    }
  }

  static bool CoversTurn(const drivers::LidarScan& scan) {
    if (scan.angles_rad.size() < 3) return false;
    double turned = 0;
    for (size_t i = 1; i < scan.angles_rad.size(); ++i) {
      turned += std::abs(motion::WrapAngle(scan.angles_rad[i] - scan.angles_rad[i - 1]));
    }
    return turned > 1.5 * M_PI;
  }

  bool Initialize(int64_t t_us, const Pose2D& odometry) {
    const int64_t max_gap = static_cast<int64_t>(options_.max_pose_gap_s * 1e6);
    Pose2D start = options_.initial_pose;
    if (options_.initial == "global") {
      slam_.InitializeGlobal(odometry);
      global_started_us_ = t_us;
      mbot::log::Info("slam: global localization with " + std::to_string(slam_.filter().particles().size()) +
                      " particles over the map's free space");
      return true;
    }
    if (options_.initial == "ground_truth" || options_.initial == "reference") {
      const auto& series = options_.initial == "ground_truth" ? ground_truth_ : reference_;
      if (!motion::InterpolateAt(series, t_us, max_gap, &start)) {
        // The series may not have reached this scan yet: take its latest pose if it is recent.
        if (series.empty() || std::llabs(series.back().t_us - t_us) > max_gap) return false;
        start = series.back().pose;
      }
    } else if (options_.initial == "odometry") {
      start = odometry;
    }
    slam_.Initialize(start, odometry, options_.initial_sigma_xy, options_.initial_sigma_theta);
    return true;
  }

  // Global-localization convergence and kidnapping: when lost was flagged, when the filter recovered.
  void TrackEvents(const ScanRecord& r) {
    const double t = (r.t_us - first_t_us_) * 1e-6;
    if (global_started_us_ >= 0 && converged_at_s_ < 0 && r.updated && r.status.converged) {
      converged_at_s_ = t;
      converged_scan_ = static_cast<int>(records_.size()) - 1;
      mbot::log::Info("slam: global localization converged after " + std::to_string(records_.size()) + " scans (" +
                      Num(t, 4) + " s), spread " + Num(r.status.spread_m, 3) + " m");
    }
    if (r.status.lost && lost_at_s_.size() == recovered_at_s_.size()) {
      lost_at_s_.push_back(t);
      lost_scan_.push_back(static_cast<int>(records_.size()) - 1);
      mbot::log::Info("slam: lost at " + Num(t, 4) + " s (inlier share " + Num(r.status.inlier_fraction, 3) + ")");
    } else if (lost_at_s_.size() > recovered_at_s_.size() && r.updated && r.status.converged && !r.status.lost &&
               r.status.inlier_fraction >= options_.slam.filter.lost_inlier_fraction) {
      recovered_at_s_.push_back(t);
      recovered_scan_.push_back(static_cast<int>(records_.size()) - 1);
      mbot::log::Info("slam: recovered at " + Num(t, 4) + " s");
    }
  }

  void WriteOutputs(const RunContext& ctx, bool interrupted, double wall_s) {
    const std::string dir = ctx.output_dir + "/";
    const int64_t max_gap = static_cast<int64_t>(options_.max_pose_gap_s * 1e6);
    const std::vector<TimedPose>& truth_series = options_.truth_is_reference ? reference_ : ground_truth_;
    const std::string truth_name = options_.truth_is_reference ? "reference" : "ground truth";

    std::vector<TimedPose> slam_path, odometry_path, truth_path;
    int unscored_late = 0;
    std::vector<Pose2D> est_paired, odo_paired, truth_paired, ref_paired, ref_truth_paired;
    for (const ScanRecord& r : records_) {
      slam_path.push_back({r.t_us, r.slam});
      odometry_path.push_back({r.t_us, r.odometry});
      Pose2D t;
      if (motion::InterpolateAt(truth_series, r.t_us, max_gap, &t)) {
        truth_path.push_back({r.t_us, t});
        const bool late = options_.score_max_latency_us > 0 && r.latency_us > options_.score_max_latency_us;
        unscored_late += late;
        if (r.t_us >= options_.score_from_us + first_t_us_ && !late) {
          est_paired.push_back(r.slam);
          odo_paired.push_back(r.odometry);
          truth_paired.push_back(t);
          Pose2D ref;
          if (!options_.truth_is_reference && motion::InterpolateAt(reference_, r.t_us, max_gap, &ref)) {
            ref_paired.push_back(ref);
            ref_truth_paired.push_back(t);
          }
        }
      }
    }
    WriteTum(dir + "slam.tum", std::string("SLAM (") + mapping::ToString(options_.slam.mode) + ")", slam_path);
    WriteTum(dir + "odometry.tum", "odometry at the scan times", odometry_path);
    WriteFileAtomically(dir + "slam_scans.csv", [&](std::ostream& o) {
      o << "t_s,x,y,theta,filter_updated,particles,ess,spread_m,inlier_fraction,fit_ratio,injected,lost,converged,update_ms\n";
      char line[256];
      for (const ScanRecord& r : records_) {
        std::snprintf(line, sizeof line, "%.6f,%.4f,%.4f,%.5f,%d,%d,%.1f,%.4f,%.3f,%.3f,%d,%d,%d,%.3f\n", r.t_us * 1e-6, r.slam.x,
                      r.slam.y, r.slam.theta, r.updated, r.status.particles, r.status.ess, r.status.spread_m,
                      r.status.inlier_fraction, r.status.fit_ratio, r.status.injected, r.status.lost, r.status.converged, r.update_ms);
        o << line;
      }
    });
    if (!truth_path.empty()) WriteTum(dir + "ground_truth.tum", truth_name + " at the scan times", truth_path);

    const mapping::OccupancyGrid& map = slam_.map();
    const std::string base = dir + options_.map_basename;
    if (options_.slam.mode != mapping::SlamMode::kLocalization) {
      drivers::WriteBotlabMap(map, base + ".map");
      drivers::WriteRosMap(map, base + ".yaml");
      if (options_.octomap_height_m > 0) drivers::WriteOctomap(map, options_.octomap_height_m, base + ".bt");
    }
    std::vector<drivers::MapOverlay> overlays;
    if (!particle_snapshots_.empty()) overlays.push_back({particle_snapshots_, 255, 160, 0, true, "particles"});
    auto poses_of = [](const std::vector<TimedPose>& s) {
      std::vector<Pose2D> v;
      for (const TimedPose& p : s) v.push_back(p.pose);
      return v;
    };
    if (!truth_path.empty()) overlays.push_back({poses_of(truth_path), 0, 170, 0, false, truth_name});
    overlays.push_back({poses_of(odometry_path), 220, 0, 0, false, "odometry"});
    overlays.push_back({poses_of(slam_path), 0, 60, 255, false, "SLAM"});
    drivers::WriteMapPngWithOverlays(map, overlays, options_.png_scale, base + ".png");

    // Map sharpness: the share of every scan's returns that end within inlier_distance_m of an
    // obstacle of the final map, at the pose the scan was given (blurred or doubled walls lower it).
    double consistency = NAN;
    if (!scan_points_.empty()) {
      consistency_model_.SetMap(map);
      double sum = 0;
      for (size_t i = 0; i < scan_points_.size(); ++i) sum += consistency_model_.InlierFraction(records_[i].slam, scan_points_[i]);
      consistency = sum / scan_points_.size();
    }
    // Metrics.
    std::vector<double> update_ms, filter_ms, ess;
    int updates = 0;
    for (const ScanRecord& r : records_) {
      update_ms.push_back(r.update_ms);
      if (r.updated) {
        ++updates;
        filter_ms.push_back(r.update_ms);
        ess.push_back(r.status.ess);
      }
    }
    const double data_s = (last_t_us_ - first_t_us_) * 1e-6;
    std::ostringstream j;
    j << "{\n  \"mode\": " << JsonString(mapping::ToString(options_.slam.mode)) << ",\n  \"seed\": " << ctx.seed
      << ",\n  \"interrupted\": " << (interrupted ? "true" : "false") << ",\n  \"source\": " << JsonString(ctx.source_path)
      << ",\n  \"scans\": " << records_.size() << ",\n  \"scans_skipped\": " << skipped_scans_
      << ",\n  \"filter_updates\": " << updates << ",\n  \"particles\": " << options_.slam.filter.particles
      << ",\n  \"truth\": " << JsonString(truth_series.empty() ? "none" : truth_name)
      << ",\n  \"scans_not_scored_late\": " << unscored_late;
    if (!est_paired.empty()) {
      const auto ate = [&](const std::vector<Pose2D>& e, const std::vector<Pose2D>& t) {
        return "{\"aligned\": " + AteJson(motion::ComputeAte(e, t, motion::AteAlignment::kBestFitSE2)) +
               ",\n    \"anchored\": " + AteJson(motion::ComputeAte(e, t, motion::AteAlignment::kFirstPose)) +
               ",\n    \"unaligned\": " + AteJson(motion::ComputeAte(e, t, motion::AteAlignment::kNone)) + "}";
      };
      j << ",\n  \"slam_ate\": " << ate(est_paired, truth_paired) << ",\n  \"odometry_ate\": " << ate(odo_paired, truth_paired);
      if (!ref_paired.empty()) j << ",\n  \"reference_ate\": " << ate(ref_paired, ref_truth_paired);
      const motion::AteResult a = motion::ComputeAte(est_paired, truth_paired, motion::AteAlignment::kBestFitSE2);
      const motion::AteResult o = motion::ComputeAte(odo_paired, truth_paired, motion::AteAlignment::kBestFitSE2);
      mbot::log::Info("slam: ATE vs " + truth_name + " (aligned, " + std::to_string(a.samples) + " scans): RMSE x " +
                      Num(a.x.rmse, 3) + " m, y " + Num(a.y.rmse, 3) + " m, xy " + Num(a.xy.rmse, 3) + " m, theta " +
                      Num(a.theta.rmse * 180 / M_PI, 3) + " deg; odometry xy " + Num(o.xy.rmse, 3) + " m, theta " +
                      Num(o.theta.rmse * 180 / M_PI, 3) + " deg");
    }
    j << ",\n  \"global_localization\": ";
    if (global_started_us_ < 0) {
      j << "null";
    } else {
      j << "{\"converged\": " << (converged_at_s_ >= 0 ? "true" : "false") << ", \"converged_at_s\": " << Num(converged_at_s_)
        << ", \"converged_at_scan\": " << converged_scan_ << "}";
    }
    j << ",\n  \"kidnapping\": ";
    if (kidnap_us_ < 0) {
      j << "null";
    } else {
      j << "{\"at_s\": " << Num((kidnap_us_ - first_t_us_) * 1e-6) << "}";
    }
    j << ",\n  \"lost\": [";
    for (size_t i = 0; i < lost_at_s_.size(); ++i) {
      j << (i ? ", " : "") << "{\"at_s\": " << Num(lost_at_s_[i]) << ", \"at_scan\": " << lost_scan_[i]
        << ", \"recovered_at_s\": " << (i < recovered_at_s_.size() ? Num(recovered_at_s_[i]) : "null")
        << ", \"scans_to_recover\": " << (i < recovered_scan_.size() ? std::to_string(recovered_scan_[i] - lost_scan_[i]) : "null")
        << "}";
    }
    j << "]";
    j << ",\n  \"effective_sample_size\": " << SampleStats::Of(ess).Json()
      << ",\n  \"timing\": {\"scan_update_ms\": " << SampleStats::Of(update_ms).Json()
      << ", \"filter_update_ms\": " << SampleStats::Of(filter_ms).Json() << ", \"wall_s\": " << Num(wall_s)
      << ", \"data_s\": " << Num(data_s) << ", \"real_time_factor\": " << Num(wall_s > 0 ? data_s / wall_s : NAN) << "}"
      << ",\n  \"map\": {\"scan_consistency\": " << Num(consistency) << ", \"width\": " << map.width() << ", \"height\": " << map.height()
      << ", \"resolution\": " << Num(map.resolution()) << ", \"origin_x\": " << Num(map.origin_x())
      << ", \"origin_y\": " << Num(map.origin_y()) << "}\n}\n";
    WriteFileAtomically(dir + "metrics.json", [&](std::ostream& o) { o << j.str(); });
    mbot::log::Info("slam: " + std::to_string(records_.size()) + " scans (" + std::to_string(updates) +
                    " filter updates), scan consistency " + Num(consistency, 3) + ", median " + Num(SampleStats::Of(update_ms).median, 3) + " ms per scan; outputs in " +
                    ctx.output_dir);
  }

  SlamStageOptions options_;
  mapping::Slam slam_;
  Bus* bus_ = nullptr;
  std::mt19937_64 noise_rng_;
  std::optional<motion::WheelOdometry> wheel_odometry_;
  std::string odometry_channel_, encoder_channel_, truth_channel_, reference_channel_, lidar_channel_;
  std::vector<TimedPose> odometry_, ground_truth_, reference_;
  Pose2D last_raw_odometry_, noisy_odometry_;
  std::deque<Pending> pending_;
  std::map<std::string, bool> stamp_channels_;  // channel → its stamps share the log's clock
  int64_t previous_scan_us_ = -1;
  int64_t first_t_us_ = -1, last_t_us_ = -1;
  int64_t kidnap_us_ = -1, global_started_us_ = -1;
  std::optional<mapping::SlamState> published_state_;
  int skipped_scans_ = 0;
  std::vector<ScanRecord> records_;
  static constexpr size_t kMaxKeptScans = 200000;
  mapping::SensorModel consistency_model_{mapping::SensorModelOptions{}};
  std::vector<mapping::ScanPoints> scan_points_;  // per record, for the map-consistency metric
  std::vector<Pose2D> particle_snapshots_;
  double converged_at_s_ = -1;
  int converged_scan_ = -1;
  std::vector<double> lost_at_s_, recovered_at_s_;
  std::vector<int> lost_scan_, recovered_scan_;
  std::chrono::steady_clock::time_point wall_start_;
};

}  // namespace

StageType SlamStageType() {
  return {"slam",
          "log-odds mapping, Monte-Carlo localization and full SLAM (mode = full_slam | localization | "
          "mapping_only | action_only); writes the map, TUM trajectories and metrics.json",
          [](config::Section& s) -> std::unique_ptr<Stage> { return std::make_unique<SlamStage>(ParseSlamStageOptions(s)); }};
}

}  // namespace mbot::app
