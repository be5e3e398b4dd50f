#include "mbot/motion/wheel_odometry.hpp"

#include <cmath>
#include <stdexcept>

namespace mbot::motion {

WheelOdometry::WheelOdometry(const WheelOdometryOptions& options) : options_(options) {
  if (options.left_m_per_tick == 0 || options.right_m_per_tick == 0 || !(options.wheel_base_m > 0)) {
    throw std::invalid_argument("wheel odometry: metres per tick must be non-zero and the wheel base positive");
  }
}

const Pose2D& WheelOdometry::Update(int64_t left_ticks, int64_t right_ticks) {
  if (!started_) {
    started_ = true;
  } else {
    const double dl = (left_ticks - left_) * options_.left_m_per_tick;
    const double dr = (right_ticks - right_) * options_.right_m_per_tick;
    const double ds = 0.5 * (dl + dr), dth = (dr - dl) / options_.wheel_base_m;
    const double mid = pose_.theta + 0.5 * dth;
    pose_.x += ds * std::cos(mid);
    pose_.y += ds * std::sin(mid);
    pose_.theta = WrapAngle(pose_.theta + dth);
  }
  left_ = left_ticks;
  right_ = right_ticks;
  return pose_;
}

}  // namespace mbot::motion
