#include "mbot/motion/wheel_odometry.hpp"

#include <cmath>
#include <stdexcept>

namespace mbot::motion {

WheelOdometry::WheelOdometry(const WheelOdometryOptions& options) : options_(options) {
  if (options.left_m_per_tick == 0 || options.right_m_per_tick == 0 || !(options.wheel_base_m > 0)) {
    throw std::invalid_argument("wheel odometry: metres per tick must be non-zero and the wheel base positive");
  }
}

WheelStep WheelOdometry::Step(int64_t left_ticks, int64_t right_ticks) {
  WheelStep step;
  if (started_) {
    const double dl = (left_ticks - left_) * options_.left_m_per_tick;
    const double dr = (right_ticks - right_) * options_.right_m_per_tick;
    step = {0.5 * (dl + dr), (dr - dl) / options_.wheel_base_m};
  }
  started_ = true;
  left_ = left_ticks;
  right_ = right_ticks;
  return step;
}

const Pose2D& WheelOdometry::Apply(const WheelStep& step) {
  const double mid = pose_.theta + 0.5 * step.turn_rad;
  pose_.x += step.distance_m * std::cos(mid);
  pose_.y += step.distance_m * std::sin(mid);
  pose_.theta = WrapAngle(pose_.theta + step.turn_rad);
  return pose_;
}

}  // namespace mbot::motion
