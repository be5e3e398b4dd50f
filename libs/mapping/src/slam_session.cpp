#include "mbot/mapping/slam_session.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string_view>

#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/common/process.hpp"
#include "mbot/common/strings.hpp"
#include "mbot/mapping/mapping_config.hpp"
#include "mbot/motion/motion_config.hpp"
#include "mbot/msgs/topics.hpp"

namespace mbot::mapping {

using motion::Pose2D;
using motion::TimedPose;
using msgs::EventKind;

SlamSessionOptions ParseSlamSessionOptions(config::Section& s) {
  SlamSessionOptions o;
  o.slam = ParseSlamOptions(s);
  o.scan = ParseScanOptions(s);
  const SlamOptions& m = o.slam;
  // Inputs.
  o.lidar_channel = s.GetString("lidar_channel", "", "lidar channel ('' = the first one seen)");
  const std::string odo = s.GetChoice("odometry", "channel", {"channel", "encoders"},
                                      "odometry from an odometry channel or integrated from encoder ticks");
  o.encoder_odometry = odo == "encoders";
  o.odometry_channel = s.GetString("odometry_channel", "",
                                   "odometry channel ('' = the scan lines' own odometry fields, <lidar>.odom, when "
                                   "the log has them, else the first one seen)");
  o.wheels = motion::ParseWheelConstants(s);  // used when odometry = encoders
  o.ground_truth_channel = s.GetString("ground_truth_channel", "", "ground-truth channel ('' = the first one seen)");
  o.reference_channel = s.GetString("reference_channel", "", "reference-pose channel ('' = the first one seen)");
  o.mapping_poses_from_reference = s.GetChoice("mapping_poses", "ground_truth", {"ground_truth", "reference"},
                                               "mapping-only: where the poses come from") == "reference";
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
                            {{"auto", BeamTiming::kAuto},
                             {"beams", BeamTiming::kBeams},
                             {"spread", BeamTiming::kSpread},
                             {"none", BeamTiming::kNone}},
                            "per-beam time: the beams' own times, spread evenly over the time since the last scan, "
                            "or none (all at the scan time); auto picks the first that applies");
  o.lidar_time_offset_us = static_cast<int64_t>(
      std::llround(s.GetDouble("lidar_time_offset_s", 0.0,
                               "added to a scan's time (its last beam) before poses are looked up", -1.0, 1.0) *
                   1e6));
  o.max_pose_gap_s =
      s.GetDouble("max_pose_gap_s", 0.5, "largest gap in a pose series to interpolate across", 0.0, 3600.0);

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
  if (o.initial == "global" && m.mode != SlamMode::kLocalization && m.mode != SlamMode::kGraphSlam && !s.describing()) {
    s.Fail("initial_pose", "global needs mode = localization or graph_slam (and a map_file)");
  }
  o.initial_sigma_xy = s.GetDouble("initial_sigma_xy_m", 0.0, "spread of the first particles around the start", 0.0);
  o.initial_sigma_theta = s.GetDouble("initial_sigma_theta_rad", 0.0, "heading spread of the first particles", 0.0);

  o.checkpoint_every_s = s.GetDouble("checkpoint_every_s", 0.0,
                                     "write the map and pose to checkpoint_file this often, in the stream's time, so "
                                     "a killed run can resume (0: never) [s]",
                                     0.0, 1e6);
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
  pert.jump_every_s = s.GetDouble("odometry_jump_every_s", 0.0,
                                  "injected odometry glitches: a jump that stays, this often (0: never) [s]", 0.0);
  pert.jump_max_m = s.GetDouble("odometry_jump_max_m", 1.0, "... of up to this length, in a random direction", 0.0);
  pert.jump_max_rad = s.GetDouble("odometry_jump_max_rad", 0.0, "... and up to this turn, either way", 0.0, M_PI);
  o.scan_every = static_cast<int>(s.GetInt(
      "scan_every", 1, "use every k-th scan of the lidar channel (others dropped: robustness tests)", 1, 1000));
  auto& scan_pert = o.scan_perturbation;
  scan_pert.glass_share = s.GetDouble("scan_glass_share", 0.0,
                                      "injected glass: the share of the walls (in 1 m patches fixed in the odometry "
                                      "frame) a beam goes through, to no return or a return 1.5-3 times as far",
                                      0.0, 1.0);
  scan_pert.people = static_cast<int>(s.GetInt(
      "scan_people", 0, "injected people: this many 0.2 m discs walking at 1 m/s within 4 m of the lidar", 0, 100));

  o.particles_every = static_cast<int>(
      s.GetInt("particles_every", o.particles_every, "draw the particles every k-th scan (0: never)", 0));
  o.publish_particles_every =
      static_cast<int>(s.GetInt("publish_particles_every", o.publish_particles_every,
                                "emit the particles (SLAM_PARTICLES) every k-th scan (0: never)", 0));
  o.publish_map_every = static_cast<int>(s.GetInt(
      "publish_map_every", o.publish_map_every,
      "emit the map to later stages (planner, explorer) every k-th scan (0: never); the pose goes every scan", 0));
  return o;
}

namespace {

void Append(std::vector<TimedPose>* series, const msgs::Event& ev) {
  if (!series->empty() && ev.t_us < series->back().t_us) return;
  series->push_back({ev.t_us, std::get<Pose2D>(ev.payload)});
}

}  // namespace

SlamInputs::SlamInputs(const SlamSessionOptions& options, uint64_t seed)
    : o_(options), perturbation_(options.perturbation, seed) {
  if (o_.encoder_odometry) wheel_odometry_.emplace(o_.wheels);
}

bool SlamInputs::Add(const msgs::Event& in) {
  if (first_t_us_ < 0) first_t_us_ = in.t_us;
  last_t_us_ = in.t_us;
  msgs::Event retimed;
  const msgs::Event& ev = Retime(in, &retimed);
  switch (ev.kind) {
    case EventKind::kOdometry:
      ++odometry_seen_[ev.channel];
      if (!o_.encoder_odometry && o_.odometry_channel.empty() && ScanLineOdometry(ev.channel)) {
        // A CARMEN scan line's own odometry fields (FLASER, ROBOTLASER1) are the odometry at the
        // scan itself; ODOM lines come in bursts. They win over an odometry channel taken earlier.
        if (!odometry_channel_.empty() && odometry_channel_ != ev.channel) {
          mbot::log::Info("slam: odometry from " + ev.channel + " (the scan lines' own fields), not " +
                          odometry_channel_);
          odometry_.clear();
          continuity_ = motion::OdometryContinuity();
        }
        odometry_channel_ = ev.channel;
      }
      if (!o_.encoder_odometry && Accept(&odometry_channel_, o_.odometry_channel, ev)) {
        AddOdometry(ev.t_us, std::get<Pose2D>(ev.payload), ev.stamp_us);
      }
      return true;
    case EventKind::kEncoders:
      if (o_.encoder_odometry && Accept(&encoder_channel_, "", ev)) {
        const auto& e = std::get<msgs::EncoderTicks>(ev.payload);
        AddOdometry(ev.t_us, wheel_odometry_->Update(e.left_ticks, e.right_ticks), ev.stamp_us);
      }
      return true;
    case EventKind::kGroundTruth:
      if (Accept(&truth_channel_, o_.ground_truth_channel, ev)) Append(&ground_truth_, ev);
      return true;
    case EventKind::kReferencePose:
      if (Accept(&reference_channel_, o_.reference_channel, ev)) Append(&reference_, ev);
      return true;
    case EventKind::kLidar:
      if (Accept(&lidar_channel_, o_.lidar_channel, ev)) {
        if (scans_seen_++ % o_.scan_every != 0) return true;
        // How late the scan arrived: its stamp is the robot's clock, its event time the logger's.
        const int64_t latency = std::llabs(in.t_us - in.stamp_us) < 2'000'000 ? in.t_us - in.stamp_us : 0;
        pending_.push_back(Scan{ev.t_us, previous_scan_us_, latency, in.stamp_us != 0 ? in.stamp_us : in.t_us,
                                std::get<msgs::LidarScan>(ev.payload)});
        previous_scan_us_ = ev.t_us;
      }
      return true;
    default: return false;
  }
}

const SlamInputs::Scan* SlamInputs::ReadyScan(bool at_end) const {
  if (pending_.empty()) return nullptr;
  const std::vector<TimedPose>& p = poses();
  const int64_t t_end = pending_.front().t_us + o_.lidar_time_offset_us;
  if (!at_end && (p.empty() || p.back().t_us < t_end)) return nullptr;  // wait for the poses to catch up
  return &pending_.front();
}

const std::vector<TimedPose>& SlamInputs::poses() const {
  return o_.slam.mode == SlamMode::kMappingOnly ? (o_.mapping_poses_from_reference ? reference_ : ground_truth_)
                                                : odometry_;
}

// The time each message is placed at: its own stamp when the channel's stamps share the log's
// clock (the robot's measurement time, immune to network bursts), else its arrival time.
const msgs::Event& SlamInputs::Retime(const msgs::Event& ev, msgs::Event* copy) {
  if (o_.time_base == "event" || ev.stamp_us == 0) return ev;
  auto it = stamp_channels_.find(ev.channel);
  if (it == stamp_channels_.end()) {
    const bool same_clock = o_.time_base == "stamp" || std::llabs(ev.stamp_us - ev.t_us) < 2'000'000;
    it = stamp_channels_.emplace(ev.channel, same_clock).first;
    if (!same_clock) mbot::log::Info("slam: " + ev.channel + " stamps use another clock; using arrival times");
  }
  if (!it->second) return ev;
  // On a channel whose stamps share the log's clock, a stamp seconds away from the arrival is corrupt:
  // placed there it would hold the pose series back (later messages look older) or jump it ahead.
  if (o_.time_base != "stamp" && std::llabs(ev.stamp_us - ev.t_us) > 2'000'000) {
    ++stamp_outliers_;
    mbot::log::WarnOnce("slam:stamp:" + ev.channel,
                        "slam: " + ev.channel + ": a stamp " + std::to_string((ev.stamp_us - ev.t_us) * 1e-6) +
                            " s from its arrival: placed at its arrival (further ones are counted)");
    return ev;
  }
  if (ev.kind != EventKind::kLidar && ev.kind != EventKind::kOdometry && ev.kind != EventKind::kEncoders &&
      ev.kind != EventKind::kGroundTruth && ev.kind != EventKind::kReferencePose) {
    return ev;
  }
  *copy = ev;
  copy->t_us = ev.stamp_us;
  return *copy;
}

// `<lidar>.odom`: the odometry fields of the chosen (or, before the first scan, any) lidar's lines.
bool SlamInputs::ScanLineOdometry(const std::string& channel) const {
  const std::string_view suffix = ".odom";
  if (channel.size() <= suffix.size() || channel.compare(channel.size() - suffix.size(), suffix.size(), suffix) != 0)
    return false;
  const std::string lidar = channel.substr(0, channel.size() - suffix.size());
  return lidar_channel_.empty() ? o_.lidar_channel.empty() || o_.lidar_channel == lidar : lidar_channel_ == lidar;
}

// Takes the first channel of a kind unless the options name one.
bool SlamInputs::Accept(std::string* chosen, const std::string& wanted, const msgs::Event& ev) {
  if (!wanted.empty()) return ev.channel == wanted;
  if (chosen->empty()) *chosen = ev.channel;
  if (*chosen == ev.channel) return true;
  mbot::log::WarnOnce("slam:" + ev.channel, "slam: " + std::string(msgs::ToString(ev.kind)) + " channel " + ev.channel +
                                                " ignored; using " + *chosen);
  return false;
}

// Odometry as the filter sees it: continuous across robot restarts, then with the configured
// perturbations (noise, a kidnapping jump).
void SlamInputs::AddOdometry(int64_t t_us, const Pose2D& raw, int64_t stamp_us) {
  if (!odometry_.empty() && t_us < odometry_.back().t_us) return;
  const int restarts = continuity_.restarts(), outliers = continuity_.outliers();
  const Pose2D continuous = continuity_.Update(t_us, raw, stamp_us);
  if (continuity_.outliers() > outliers) {
    mbot::log::WarnOnce("slam:odometry_outlier",
                        "slam: an odometry message that jumps away and back (corrupt) is "
                        "dropped; further ones are counted");
  }
  if (continuity_.restarts() > restarts) {
    restart_times_.push_back(continuity_.last_restart_us());
    if (restart_times_.size() > 64) restart_times_.pop_front();
    const motion::OdometryContinuity::Restart& j = continuity_.last_restart();
    auto pose = [&](const Pose2D& p, int64_t t) {
      return "(" + Significant(p.x, 4) + ", " + Significant(p.y, 4) + ", " + Significant(p.theta, 3) + " rad at " +
             Significant((t - first_t_us_) * 1e-6, 6) + " s)";
    };
    mbot::log::Warn(
        "slam: odometry jumped by more than a robot can move at " + std::to_string((t_us - first_t_us_) * 1e-6) +
        " s (a robot restart?): continuing from the pose before the jump; raw " + pose(j.before, j.before_us) +
        " then " + pose(j.jumped, j.jumped_us) + ", confirmed by " + pose(j.confirmed, j.confirmed_us));
  }
  const Pose2D out = perturbation_.Apply(t_us, first_t_us_, continuous);
  odometry_.push_back({t_us, out});
}

OdometryDoubt SlamInputs::PosesDoubtful(int64_t from_us, int64_t to_us, int64_t max_gap_us) const {
  OdometryDoubt out;
  for (const int64_t r : restart_times_) {
    if (r > from_us && r <= to_us) return {true, -1.0};
  }
  const std::vector<TimedPose>& series = poses();
  auto k =
      std::lower_bound(series.begin(), series.end(), from_us, [](const TimedPose& p, int64_t t) { return p.t_us < t; });
  if (k != series.begin()) --k;
  // The gaps that end after `from_us` (one that ended at the last scan was that scan's).
  for (; k != series.end() && k + 1 != series.end() && k->t_us <= to_us; ++k) {
    const int64_t gap = (k + 1)->t_us - k->t_us;
    if ((k + 1)->t_us > from_us && gap > max_gap_us) {
      out.doubtful = true;
      out.unobserved_s = std::max(out.unobserved_s, gap * 1e-6);
    }
  }
  return out;
}

void SlamInputs::TrimBefore(int64_t t_us) {
  constexpr size_t kBatch = 4096;  // erase in batches: the vectors are scanned, not shifted, per call
  for (std::vector<TimedPose>* series : {&odometry_, &ground_truth_, &reference_}) {
    const auto first_kept = std::lower_bound(series->begin(), series->end(), t_us,
                                             [](const TimedPose& p, int64_t t) { return p.t_us < t; });
    const size_t drop = first_kept == series->begin() ? 0 : static_cast<size_t>(first_kept - series->begin()) - 1;
    if (drop >= kBatch) series->erase(series->begin(), series->begin() + static_cast<std::ptrdiff_t>(drop));
  }
}

SlamSession::SlamSession(const SlamSessionOptions& options, uint64_t seed, std::optional<OccupancyGrid> known_map)
    : o_(options),
      slam_(options.slam, seed),
      inputs_(options, seed),
      events_(options.slam.filter.lost_inlier_fraction),
      consistency_model_(options.slam.sensor),
      scan_perturbation_(options.scan_perturbation, seed) {
  if (known_map && options.slam.mode == SlamMode::kGraphSlam) {
    global_map_ = std::move(known_map);
  } else if (known_map) {
    slam_.SetMap(std::move(*known_map));
  }
}

void SlamSession::Add(const msgs::Event& event, std::vector<msgs::Event>* out) {
  if (event.kind == EventKind::kSlamControl) {
    if (const auto* c = std::get_if<msgs::SlamControl>(&event.payload)) Control(*c);
    return;
  }
  if (inputs_.Add(event)) ProcessReadyScans(false, out);
}

void SlamSession::Control(const msgs::SlamControl& c) {
  // A person at the viewer: what the mode cannot do is said and left; the status goes out again
  // with the next scan either way, so the viewer shows what holds.
  try {
    if (c.mapping) slam_.SetMapping(*c.mapping);
    if (c.localization) slam_.SetLocalization(*c.localization);
    if (c.clear_map) slam_.ClearMap(), map_due_ = true;
    mbot::log::Info(std::string("slam: mapping ") + (slam_.mapping_on() ? "on" : "off") + ", localization " +
                    (slam_.localization_on() ? "on" : "off") + (c.clear_map ? ", map cleared" : ""));
  } catch (const std::invalid_argument& e) {
    mbot::log::Warn(std::string("slam: ") + e.what());
  }
  status_due_ = true;
}

void SlamSession::Finish(std::vector<msgs::Event>* out) {
  ProcessReadyScans(true, out);
  // Graph SLAM's poses are final only once the last loops are closed and the graph is solved.
  slam_.Finish();
  const std::vector<Pose2D> poses = slam_.Trajectory();
  // Graph SLAM holds every record until now (released_ is 0), so record i is node i.
  for (size_t i = released_; i - released_ < records_.size() && i < poses.size(); ++i)
    records_[i - released_].slam = poses[i];
  for (auto& item : scan_sample_.mutable_items())
    if (item.index < poses.size()) item.value.pose = poses[item.index];
  if (!records_.empty()) last_record_ = records_.back();
  const int64_t max_gap = static_cast<int64_t>(o_.max_pose_gap_s * 1e6);
  if (sink_)
    while (!records_.empty()) ReleaseFront(max_gap);
}

void SlamSession::ProcessReadyScans(bool at_end, std::vector<msgs::Event>* out) {
  while (const SlamInputs::Scan* p = inputs_.ReadyScan(at_end)) {
    ProcessScan(*p, p->t_us + o_.lidar_time_offset_us, out);
    inputs_.PopScan();
  }
}

void SlamSession::ProcessScan(const SlamInputs::Scan& p, int64_t t_end, std::vector<msgs::Event>* out) {
  const std::vector<TimedPose>& poses = inputs_.poses();
  const msgs::LidarScan& scan = p.scan;
  // When was each beam measured, as a fraction of the scan's duration?
  const BeamTimes beams =
      TimeBeams(o_.beam_timing, scan.angles_rad, scan.beam_times_us, p.previous_us >= 0 ? p.t_us - p.previous_us : 0);
  if (beams.beam_times_unusable) {
    mbot::log::WarnOnce("slam:beam_times",
                        "slam: beam_timing = beams, but this scan's beam times do not span the scan");
  }
  const std::vector<float>& fractions = beams.fractions;
  const int64_t duration = beams.duration_us;
  const int64_t max_gap = static_cast<int64_t>(o_.max_pose_gap_s * 1e6);
  Pose2D end_pose, start_pose;
  if (!motion::InterpolateAt(poses, t_end, max_gap, &end_pose) ||
      !motion::InterpolateAt(poses, t_end - duration, max_gap, &start_pose)) {
    ++skipped_scans_;
    return;
  }
  const Pose2D sensor = o_.lidar_pose_from_scan ? scan.sensor_pose : o_.lidar_pose;
  const std::vector<float>* ranges = &scan.ranges_m;
  std::vector<float> perturbed;
  if (o_.scan_perturbation.any()) {
    perturbed = scan.ranges_m;
    scan_perturbation_.Apply(t_end, end_pose.Compose(sensor), scan.angles_rad, scan.max_range_m, &perturbed);
    ranges = &perturbed;
  }
  const auto wall0 = std::chrono::steady_clock::now();
  const std::vector<ScanRay> rays = DeskewScan(
      *ranges, scan.angles_rad, fractions, end_pose.Inverse().Compose(start_pose), sensor, scan.max_range_m, o_.scan);
  if (!slam_.initialized() && !Initialize(t_end, end_pose, rays)) {
    ++skipped_scans_;
    return;
  }
  const bool mapping_only = o_.slam.mode == SlamMode::kMappingOnly;
  // Graph SLAM searches widely where the odometry since the last scan crossed a gap or a restart.
  const double gap_s = o_.slam.graph.recover_gap_s;
  const OdometryDoubt doubt = o_.slam.mode == SlamMode::kGraphSlam && gap_s > 0 && last_scan_end_us_ >= 0
                                  ? inputs_.PosesDoubtful(last_scan_end_us_, t_end, static_cast<int64_t>(gap_s * 1e6))
                                  : OdometryDoubt{};
  last_scan_end_us_ = t_end;
  const SlamStep step = slam_.ProcessScan(rays, end_pose, mapping_only ? &end_pose : nullptr, doubt, t_end * 1e-6);
  if (step.gated) {
    mbot::log::WarnOnce("slam:gated",
                        "slam: a scan fitting the map at under " + Significant(o_.slam.gate_fit_ratio, 3) +
                            " of the recent scans' fit was not mapped (corrupt or misplaced; gate_fit_ratio); further "
                            "ones are counted in metrics.json (scans_gated)");
  }
  const size_t index = scans_processed();
  if (scan_sample_.Wants(index)) scan_sample_.Add(index, SampledScan{step.pose, consistency_model_.Prepare(rays)});
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall0).count();

  ScanRecord r;
  r.t_us = t_end;
  r.stamp_us = p.stamp_us + o_.lidar_time_offset_us;
  r.slam = step.pose;
  r.updated = step.filter_updated;
  r.status = step.status;
  r.update_ms = ms;
  r.latency_us = p.latency_us;
  if (index % 64 == 0) rss_mb_ = ResidentMemoryMb();
  r.rss_mb = rss_mb_;
  Pose2D odo;
  r.odometry = motion::InterpolateAt(inputs_.odometry(), t_end, max_gap, &odo) ? odo : end_pose;
  records_.push_back(r);
  last_record_ = r;
  Publish(r, out);
  if (o_.particles_every > 0 && slam_.HasParticles() && scans_processed() % o_.particles_every == 1) {
    for (const Particle& q : slam_.filter().particles()) particle_snapshots_.push_back(q.pose);
  }
  // Global-localization convergence and kidnapping: when lost was flagged, when the filter recovered.
  const std::string said =
      events_.Add((r.t_us - inputs_.first_t_us()) * 1e-6, static_cast<int>(index), r.updated, r.status);
  if (!said.empty()) mbot::log::Info("slam: " + said);
  // The map and pose, every checkpoint_every_s of the stream's time, for a run that has to resume.
  if (on_checkpoint_ && o_.checkpoint_every_s > 0 &&
      (last_checkpoint_us_ < 0 || r.t_us - last_checkpoint_us_ >= o_.checkpoint_every_s * 1e6)) {
    last_checkpoint_us_ = r.t_us;
    on_checkpoint_(SlamCheckpointState{r.slam, r.odometry, (r.t_us - inputs_.first_t_us()) * 1e-6,
                                       static_cast<long long>(scans_processed())},
                   slam_.map());
  }
  PairRecordsAndTrim(t_end - duration, max_gap);
}

void SlamSession::PairRecordsAndTrim(int64_t scan_start_us, int64_t max_gap_us) {
  std::deque<ScanRecord>* records = &records_;
  auto pair = [&](const std::vector<TimedPose>& series, size_t* next, std::optional<Pose2D> ScanRecord::*field) {
    while (*next < records->size() && !series.empty() && series.back().t_us >= (*records)[*next].t_us) {
      Pose2D p;
      if (motion::InterpolateAt(series, (*records)[*next].t_us, max_gap_us, &p)) (*records)[*next].*field = p;
      ++*next;
    }
    // A series that has not started holds nothing to wait for: waiting on it held every series at
    // the first scan, so a run without a reference (or without truth) never trimmed them (an
    // 8-hour soak grew by 27 MB an hour).
    if (series.empty()) return INT64_MAX;
    return *next < records->size() ? (*records)[*next].t_us : INT64_MAX;
  };
  const int64_t waiting = std::min(pair(inputs_.ground_truth(), &paired_truth_, &ScanRecord::truth),
                                   pair(inputs_.reference(), &paired_reference_, &ScanRecord::reference));
  inputs_.TrimBefore(std::min(waiting, scan_start_us) - 2 * max_gap_us);
  // Graph SLAM's poses change until Finish: its records are held.
  if (!sink_ || o_.slam.mode == SlamMode::kGraphSlam) return;
  // A record goes once both series have passed it, or once it is so old that a pose for it
  // arriving now would be far later than any stream delivers (a series that stopped, or never ran).
  const int64_t give_up_us = scan_start_us - (std::min<int64_t>(4 * max_gap_us, 60'000'000) + 1'000'000);
  while (!records_.empty() && ((paired_truth_ > 0 && paired_reference_ > 0) || records_.front().t_us < give_up_us))
    ReleaseFront(max_gap_us);
}

void SlamSession::ReleaseFront(int64_t max_gap_us) {
  ScanRecord& r = records_.front();
  // The last chance to pair it (at Finish, or a series that never passed it).
  Pose2D p;
  if (!r.truth && motion::InterpolateAt(inputs_.ground_truth(), r.t_us, max_gap_us, &p)) r.truth = p;
  if (!r.reference && motion::InterpolateAt(inputs_.reference(), r.t_us, max_gap_us, &p)) r.reference = p;
  sink_(r);
  records_.pop_front();
  ++released_;
  if (paired_truth_ > 0) --paired_truth_;
  if (paired_reference_ > 0) --paired_reference_;
}

bool SlamSession::Initialize(int64_t t_us, const Pose2D& odometry, const std::vector<ScanRay>& rays) {
  const int64_t max_gap = static_cast<int64_t>(o_.max_pose_gap_s * 1e6);
  Pose2D start = o_.initial_pose;
  if (o_.initial == "global" && o_.slam.mode == SlamMode::kGraphSlam) {
    if (!global_map_) throw std::invalid_argument("slam: initial_pose = global needs a map to search (map_file)");
    const GraphSlamOptions& g = o_.slam.graph;
    const std::vector<Point2> points = ScanHitPoints(rays, g.loop_point_spacing_m);
    if (static_cast<int>(points.size()) < g.min_points) return false;  // too sparse: the next scan
    const auto w0 = std::chrono::steady_clock::now();
    const MatchResult m = GlobalMatch(*global_map_, points, g.field_sigma_m, 0, g.loop_min_score);
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
    if (!m.found) {
      throw std::runtime_error(
          "slam: the whole-map search found no pose where the first scan (" + std::to_string(points.size()) +
          " returns) scores graph_loop_min_score = " + Significant(g.loop_min_score, 3) + " on " + o_.known_map_name);
    }
    mbot::log::Info("slam: found on the map by a whole-map search at (" + Significant(m.pose.x, 4) + ", " +
                    Significant(m.pose.y, 4) + ", " + Significant(m.pose.theta * 180 / M_PI, 4) + " deg), score " +
                    Significant(m.score, 3) + ", in " + Significant(wall_s, 3) + " s");
    global_map_.reset();
    slam_.Initialize(m.pose, odometry, 0, 0);
    return true;
  }
  if (o_.initial == "global") {
    slam_.InitializeGlobal(odometry);
    events_.GlobalStarted();
    mbot::log::Info("slam: global localization with " + std::to_string(slam_.filter().particles().size()) +
                    " particles over the map's free space");
    return true;
  }
  if (o_.initial == "ground_truth" || o_.initial == "reference") {
    const auto& series = o_.initial == "ground_truth" ? inputs_.ground_truth() : inputs_.reference();
    if (!motion::InterpolateAt(series, t_us, max_gap, &start)) {
      // The series may not have reached this scan yet: take its latest pose if it is recent.
      if (series.empty() || std::llabs(series.back().t_us - t_us) > max_gap) return false;
      start = series.back().pose;
    }
  } else if (o_.initial == "odometry") {
    start = odometry;
  } else if (o_.resume_odometry) {
    // Resuming: the robot may have moved since the checkpoint; its odometry says how far, unless
    // it restarted too (then its odometry is in a new frame and the checkpoint's pose is the guess).
    const Pose2D moved = o_.resume_odometry->Inverse().Compose(odometry);
    if (std::hypot(moved.x, moved.y) < 2.0) start = start.Compose(moved);
  }
  slam_.Initialize(start, odometry, o_.initial_sigma_xy, o_.initial_sigma_theta);
  return true;
}

void SlamSession::Publish(const ScanRecord& r, std::vector<msgs::Event>* out) {
  out->push_back(msgs::Event{r.t_us, r.t_us, msgs::topics::kSlamPose, EventKind::kPoseEstimate, r.slam});
  const bool builds_map = slam_.BuildsMap();
  // What the pose is worth, on change: a global search that has not settled gives no usable pose.
  const SlamState state = StateOf(o_.slam.mode, r.status);
  if (state != published_state_ || status_due_) {
    published_state_ = state;
    status_due_ = false;
    out->push_back(
        msgs::Event{r.t_us, r.t_us, msgs::topics::kSlamStatus, EventKind::kSlamStatus,
                    SlamStatus{state, o_.slam.mode, r.status.spread_m, slam_.mapping_on(), slam_.localization_on()}});
  }
  const size_t scans = scans_processed();
  if (o_.publish_particles_every > 0 && slam_.HasParticles() && scans % o_.publish_particles_every == 0) {
    msgs::Particles p;
    for (const Particle& q : slam_.filter().particles()) p.poses.push_back(q.pose), p.weights.push_back(q.weight);
    out->push_back(msgs::Event{r.t_us, r.t_us, msgs::topics::kSlamParticles, EventKind::kParticles, std::move(p)});
  }
  if (o_.publish_map_every > 0 && (scans == 1 || map_due_ || (builds_map && scans % o_.publish_map_every == 0))) {
    map_due_ = false;
    out->push_back(msgs::Event{r.t_us, r.t_us, msgs::topics::kSlamMap, EventKind::kMap,
                               std::make_shared<const OccupancyGrid>(slam_.map())});
  }
}

std::string NoScanProcessedReason(const SlamSession& session) {
  const SlamInputs& in = session.inputs();
  const SlamSessionOptions& o = session.options();
  if (in.scans_seen() == 0) {
    return in.lidar_channel().empty() && o.lidar_channel.empty()
               ? std::string("no scan was processed: the input has no lidar channel")
               : "no scan was processed: no scan arrived on lidar channel '" +
                     (o.lidar_channel.empty() ? in.lidar_channel() : o.lidar_channel) + "'";
  }
  std::string why = "no scan was processed: " + std::to_string(in.scans_seen()) + " scans on '" + in.lidar_channel() +
                    "', " + std::to_string(session.skipped_scans()) + " of them without a pose";
  if (o.slam.mode == SlamMode::kMappingOnly)
    return why + " (mapping_only takes its poses from the " +
           (o.mapping_poses_from_reference ? "reference" : "ground truth") + " channel)";
  if (o.encoder_odometry) return why + " (odometry = encoders: no encoder ticks arrived)";
  std::string seen;
  for (const auto& [channel, n] : in.odometry_channels_seen()) {
    seen += (seen.empty() ? "" : ", ") + channel + " (" + std::to_string(n) + ")";
  }
  const std::string wanted = o.odometry_channel.empty() ? in.odometry_channel() : o.odometry_channel;
  if (seen.empty()) return why + ": the input has no odometry channel";
  if (!wanted.empty() && !in.odometry_channels_seen().count(wanted)) {
    return why + ": odometry_channel = " + wanted + " is not in the input, which has " + seen;
  }
  return why + ": odometry on " + wanted +
         " did not cover the scans' times within max_pose_gap_s = " + std::to_string(o.max_pose_gap_s) +
         " (odometry channels: " + seen + ")";
}

}  // namespace mbot::mapping
