#include "mbot/motion/odometry_continuity.hpp"

#include <algorithm>
#include <cmath>

namespace mbot::motion {
namespace {

constexpr double kFarM = 1e5;  // no MBot odometry reaches this far: a corrupt message

bool Far(const Pose2D& p) { return !(std::abs(p.x) < kFarM && std::abs(p.y) < kFarM && std::isfinite(p.theta)); }

}  // namespace

bool OdometryContinuity::Jump(const Pose2D& from, const Pose2D& to, int64_t gap_us) const {
  const double gap_s = std::max(0.0, gap_us * 1e-6);
  const Pose2D step = from.Inverse().Compose(to);
  return std::hypot(step.x, step.y) > o_.max_step_m + o_.max_speed_m_s * gap_s ||
         std::abs(WrapAngle(step.theta)) > o_.max_turn_rad + o_.max_turn_rate_rad_s * gap_s;
}

Pose2D OdometryContinuity::Update(int64_t t_us, const Pose2D& raw) {
  if (!started_) {
    if (Far(raw)) {
      ++outliers_;
      return raw;
    }
    started_ = true;
    last_t_us_ = t_us;
    last_raw_ = raw;
    return raw;
  }
  if (Far(raw)) {  // never a pose to continue from
    ++outliers_;
    return offset_.Compose(last_raw_);
  }
  if (candidate_) {
    candidate_ = false;
    if (!Jump(candidate_raw_, raw, t_us - candidate_t_us_)) {
      // A restart: continue from where the robot was, so offset ⊕ candidate = offset ⊕ last raw.
      offset_ = offset_.Compose(last_raw_).Compose(candidate_raw_.Inverse());
      ++restarts_;
      last_restart_us_ = candidate_t_us_;
      last_t_us_ = t_us;
      last_raw_ = raw;
      return offset_.Compose(raw);
    }
    ++outliers_;  // the jump was one corrupt message; judge this one against the pose before it
  }
  if (Jump(last_raw_, raw, t_us - last_t_us_)) {
    candidate_ = true;
    candidate_raw_ = raw;
    candidate_t_us_ = t_us;
    return offset_.Compose(last_raw_);  // no motion until the next message tells which it was
  }
  last_t_us_ = t_us;
  last_raw_ = raw;
  return offset_.Compose(raw);
}

}  // namespace mbot::motion
