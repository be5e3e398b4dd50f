#include "slam_inputs.hpp"

#include <algorithm>

#include <cstdlib>

#include "mbot/common/log.hpp"

namespace mbot::app {
namespace {

using drivers::EventKind;
using motion::Pose2D;
using motion::TimedPose;

void Append(std::vector<TimedPose>* series, const drivers::Event& ev) {
  if (!series->empty() && ev.t_us < series->back().t_us) return;
  series->push_back({ev.t_us, std::get<Pose2D>(ev.payload)});
}

}  // namespace

SlamInputs::SlamInputs(const SlamStageOptions& options, uint64_t seed)
    : o_(options), perturbation_(options.perturbation, seed) {
  if (o_.encoder_odometry) wheel_odometry_.emplace(o_.wheels);
}

bool SlamInputs::Add(const drivers::Event& in) {
  if (first_t_us_ < 0) first_t_us_ = in.t_us;
  last_t_us_ = in.t_us;
  drivers::Event retimed;
  const drivers::Event& ev = Retime(in, &retimed);
  switch (ev.kind) {
    case EventKind::kOdometry:
      if (!o_.encoder_odometry && Accept(&odometry_channel_, o_.odometry_channel, ev)) {
        AddOdometry(ev.t_us, std::get<Pose2D>(ev.payload));
      }
      return true;
    case EventKind::kEncoders:
      if (o_.encoder_odometry && Accept(&encoder_channel_, "", ev)) {
        const auto& e = std::get<drivers::EncoderTicks>(ev.payload);
        AddOdometry(ev.t_us, wheel_odometry_->Update(e.left_ticks, e.right_ticks));
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
        // How late the scan arrived: its stamp is the robot's clock, its event time the logger's.
        const int64_t latency = std::llabs(in.t_us - in.stamp_us) < 2'000'000 ? in.t_us - in.stamp_us : 0;
        pending_.push_back(Scan{ev.t_us, previous_scan_us_, latency, in.stamp_us != 0 ? in.stamp_us : in.t_us,
                                std::get<drivers::LidarScan>(ev.payload)});
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
  return o_.slam.mode == mapping::SlamMode::kMappingOnly
             ? (o_.mapping_poses_from_reference ? reference_ : ground_truth_)
             : odometry_;
}

// The time each message is placed at: its own stamp when the channel's stamps share the log's
// clock (the robot's measurement time, immune to network bursts), else its arrival time.
const drivers::Event& SlamInputs::Retime(const drivers::Event& ev, drivers::Event* copy) {
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

// Takes the first channel of a kind unless the options name one.
bool SlamInputs::Accept(std::string* chosen, const std::string& wanted, const drivers::Event& ev) {
  if (!wanted.empty()) return ev.channel == wanted;
  if (chosen->empty()) *chosen = ev.channel;
  if (*chosen == ev.channel) return true;
  mbot::log::WarnOnce("slam:" + ev.channel, "slam: " + std::string(drivers::ToString(ev.kind)) + " channel " +
                                                ev.channel + " ignored; using " + *chosen);
  return false;
}

// Odometry as the filter sees it: continuous across robot restarts, then with the configured
// perturbations (noise, a kidnapping jump).
void SlamInputs::AddOdometry(int64_t t_us, const Pose2D& raw) {
  if (!odometry_.empty() && t_us < odometry_.back().t_us) return;
  const int restarts = continuity_.restarts(), outliers = continuity_.outliers();
  const Pose2D continuous = continuity_.Update(t_us, raw);
  if (continuity_.outliers() > outliers) {
    mbot::log::WarnOnce("slam:odometry_outlier",
                        "slam: an odometry message that jumps away and back (corrupt) is "
                        "dropped; further ones are counted");
  }
  if (continuity_.restarts() > restarts) {
    mbot::log::Warn("slam: odometry jumped by more than a robot can move at " +
                    std::to_string((t_us - first_t_us_) * 1e-6) +
                    " s (a robot restart?): continuing from the pose before the jump");
  }
  const Pose2D out = perturbation_.Apply(t_us, first_t_us_, continuous);
  odometry_.push_back({t_us, out});
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

}  // namespace mbot::app
