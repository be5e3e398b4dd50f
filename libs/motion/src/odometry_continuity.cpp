#include "mbot/motion/odometry_continuity.hpp"

#include <algorithm>
#include <cmath>

namespace mbot::motion {

Pose2D OdometryContinuity::Update(int64_t t_us, const Pose2D& raw) {
  if (!started_) {
    started_ = true;
    last_t_us_ = t_us;
    last_raw_ = raw;
    return raw;
  }
  const double gap_s = std::max(0.0, (t_us - last_t_us_) * 1e-6);
  const Pose2D step = last_raw_.Inverse().Compose(raw);
  const double dist = std::hypot(step.x, step.y);
  const double turn = std::abs(WrapAngle(step.theta));
  if (dist > o_.max_step_m + o_.max_speed_m_s * gap_s || turn > o_.max_turn_rad + o_.max_turn_rate_rad_s * gap_s) {
    // Continue from where the robot was: offset ⊕ raw now equals offset ⊕ last raw before.
    offset_ = offset_.Compose(last_raw_).Compose(raw.Inverse());
    ++restarts_;
    last_restart_us_ = t_us;
  }
  last_t_us_ = t_us;
  last_raw_ = raw;
  return offset_.Compose(raw);
}

}  // namespace mbot::motion
