// Heavy Lift, approach and engage: at the stand-off look, refine, line up, then servo along the
// face's normal (tines in, or the carried crate over the other).
#include <algorithm>
#include <cmath>

#include "heavy_lift_task.hpp"
#include "mbot/common/strings.hpp"

namespace mbot::mission::heavy_lift {

// At the stand-off: look, refine, and either go in or line up again.
bool HeavyLiftTask::Look(Mission& m, const Pose2D& pose) {
  m.Hold();
  const CrateEstimate& e = crates_[target()];
  if (!picking()) {
    // Up to the stacking height first (the carried crate then clears the other's top).
    Fork(m, o_.stack_height_m);
    const std::optional<ForkliftState>& f = m.forklift();
    if (!f || std::abs(f->height_m - o_.stack_height_m) > 0.003) {
      phase_us_ = m.now_us();
      return false;
    }
  }
  if ((m.now_us() - phase_us_) * 1e-6 < o_.look_s) return false;
  const Pose2D c = e.Get();
  normal_ = c.theta + kQuarter * std::round(motion::WrapAngle(normal_ - c.theta) / kQuarter);
  const double gap = picking() ? o_.standoff_m : o_.place_standoff_m;
  const Pose2D goal = StandOff(c, normal_, gap);
  const Pose2D off = goal.Inverse().Compose(pose);
  const bool lined_up = std::abs(off.y) <= o_.align_lateral_m &&
                        std::abs(off.theta) <= o_.align_heading_deg * M_PI / 180 && std::abs(off.x) <= 0.05;
  if (!lined_up && realigns_ < 3) {
    ++realigns_;
    m.SetGoal(goal);
    m.SetPath({goal});
    m.SetState(MissionState::kDriving, "lining up with " + Name() + " (off by " + Significant(off.y * 100, 2) +
                                           " cm, " + Significant(off.theta * 180 / M_PI, 2) + " deg)");
    phase_ = Phase::kToStandOff;
    return false;
  }
  realigns_ = 0;
  line_ = goal;
  // Picking: the tips to insert_depth past the face. Placing: the carried crate over the other.
  line_end_ = gap + (picking() ? o_.insert_depth_m : 0.0);
  m.SetState(picking() ? MissionState::kLifting : MissionState::kSettingDown,
             (picking() ? "tines into " : "carrying ") + Name());
  phase_ = Phase::kIn;
  phase_us_ = m.now_us();
  progress_ = {m.now_us(), -1e9};
  return false;
}

// Drive along line_ (forward or back) to `end` along it, steering onto it; true once there or
// stopped (no progress for a second: the tines are fully in, or something is in the way).
bool HeavyLiftTask::FollowLine(Mission& m, const Pose2D& pose, double end, bool forward) {
  const Pose2D d = line_.Inverse().Compose(pose);
  const double sign = forward ? 1.0 : -1.0;
  if (sign * (d.x - end) >= 0) return true;
  if (std::abs(d.x - progress_.second) > 0.002) progress_ = {m.now_us(), d.x};
  if ((m.now_us() - progress_.first) * 1e-6 > 1.0) return true;
  const double want = -sign * std::atan(10.0 * d.y) * 0.5;  // heading that brings it back onto the line
  const double w = std::clamp(3.0 * motion::WrapAngle(want - d.theta), -0.6, 0.6);
  const double v = sign * std::min(o_.approach_speed_m_s, 0.02 + 0.5 * std::abs(d.x - end));
  m.Drive(v, w);
  return false;
}

bool HeavyLiftTask::In(Mission& m, const Pose2D& pose) {
  if (!FollowLine(m, pose, line_end_, true)) return false;
  m.Hold();
  phase_ = picking() ? Phase::kLift : Phase::kSetDown;
  phase_us_ = m.now_us();
  Fork(m, picking() ? o_.carry_height_m : 0.0);
  inserted_ = std::hypot(pose.x - line_.x, pose.y - line_.y) - o_.standoff_m;
  return false;
}

}  // namespace mbot::mission::heavy_lift
