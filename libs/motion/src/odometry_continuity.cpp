#include "mbot/motion/odometry_continuity.hpp"

#include <algorithm>
#include <cmath>

namespace mbot::motion {
namespace {

constexpr double kFarM = 1e5;  // no MBot odometry reaches this far: a corrupt message
// Nor turns this far (a heading kept unwrapped reaches 1e5 rad after a day of turning at 1 rad/s).
// A corrupt exponent gives 1e18 and more, and a heading that large wraps to anything: taken, it made
// the next real message look like a jump, which the one after confirmed as a restart.
constexpr double kFarRad = 1e5;

bool Far(const Pose2D& p) { return !(std::abs(p.x) < kFarM && std::abs(p.y) < kFarM && std::abs(p.theta) < kFarRad); }

}  // namespace

bool OdometryContinuity::Jump(const Pose2D& from, const Pose2D& to, int64_t gap_us) const {
  const double gap_s = std::max(0.0, gap_us * 1e-6);
  const Pose2D step = from.Inverse().Compose(to);
  return std::hypot(step.x, step.y) > o_.max_step_m + o_.max_speed_m_s * gap_s ||
         std::abs(WrapAngle(step.theta)) > o_.max_turn_rad + o_.max_turn_rate_rad_s * gap_s;
}

Pose2D OdometryContinuity::Update(int64_t t_us, const Pose2D& raw, int64_t stamp_us) {
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
  // The jump's own message again (a bus duplicates what it corrupted as readily as anything else):
  // it confirms nothing. A restart is confirmed only by a later message that agrees.
  if (candidate_ && (t_us <= candidate_t_us_ || (stamp_us != 0 && stamp_us == candidate_stamp_us_))) {
    ++duplicates_;
    return offset_.Compose(last_raw_);
  }
  if (candidate_) {
    candidate_ = false;
    // A restart when this message agrees with the jumped-to pose and not with the pose before the
    // jump (a corrupt jump's heading can lie within a loose allowance of both).
    const bool agrees = !Jump(candidate_raw_, raw, t_us - candidate_t_us_) && Jump(last_raw_, raw, t_us - last_t_us_);
    // Unless the last message taken was the odd one: corrupt by too little to be a jump itself, so
    // the real pose after it looked like one. Then the jump continues from the message before.
    if (agrees && has_previous_ && !Jump(previous_raw_, candidate_raw_, candidate_t_us_ - previous_t_us_)) {
      ++outliers_;
      previous_t_us_ = candidate_t_us_, previous_raw_ = candidate_raw_;
      last_t_us_ = t_us;
      last_raw_ = raw;
      return offset_.Compose(raw);
    }
    if (agrees) {
      // A restart: continue from where the robot was, so offset ⊕ candidate = offset ⊕ last raw.
      offset_ = offset_.Compose(last_raw_).Compose(candidate_raw_.Inverse());
      ++restarts_;
      last_restart_us_ = candidate_t_us_;
      last_restart_ = {last_raw_, candidate_raw_, raw, last_t_us_, candidate_t_us_, t_us};
      has_previous_ = false;  // the pose before is in the old frame
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
    candidate_stamp_us_ = stamp_us;
    return offset_.Compose(last_raw_);  // no motion until the next message tells which it was
  }
  previous_t_us_ = last_t_us_, previous_raw_ = last_raw_, has_previous_ = true;
  last_t_us_ = t_us;
  last_raw_ = raw;
  return offset_.Compose(raw);
}

}  // namespace mbot::motion
