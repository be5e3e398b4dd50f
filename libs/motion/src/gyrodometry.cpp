#include "mbot/motion/gyrodometry.hpp"

#include <cmath>

namespace mbot::motion {

Gyrodometry::Gyrodometry(const WheelOdometryOptions& wheels, const GyrodometryOptions& options)
    : wheels_(wheels), options_(options) {}

void Gyrodometry::AddImu(int64_t t_us, double rate, double yaw, bool has_yaw) {
  rate *= options_.gyro_scale;
  if (!moved_ && options_.estimate_bias && started_) {
    bias_sum_ += rate;
    ++bias_count_;
  }
  if (have_rate_ && t_us > last_imu_us_) {
    // Trapezoid between samples, bias removed.
    gyro_turn_ += 0.5 * (rate + last_rate_ - 2.0 * gyro_bias_rad_s()) * (t_us - last_imu_us_) * 1e-6;
  }
  have_rate_ = true;
  last_rate_ = rate;
  last_imu_us_ = t_us;
  if (has_yaw) {
    if (have_yaw_) yaw_turn_ += WrapAngle(yaw - last_yaw_);
    have_yaw_ = true;
    last_yaw_ = yaw;
  }
}

const Pose2D& Gyrodometry::AddEncoders(int64_t t_us, int64_t left_ticks, int64_t right_ticks) {
  if (!started_) {
    started_ = true;
    left_ = left_ticks;
    right_ = right_ticks;
    last_enc_us_ = t_us;
    gyro_turn_ = yaw_turn_ = 0.0;
    return pose_;
  }
  const double dl = (left_ticks - left_) * wheels_.left_m_per_tick;
  const double dr = (right_ticks - right_) * wheels_.right_m_per_tick;
  left_ = left_ticks;
  right_ = right_ticks;
  moved_ = moved_ || dl != 0.0 || dr != 0.0;
  const double dt = (t_us - last_enc_us_) * 1e-6;
  last_enc_us_ = t_us;
  const double ds = 0.5 * (dl + dr);
  const double turn_enc = (dr - dl) / wheels_.wheel_base_m;
  double turn = turn_enc;
  switch (options_.heading) {
    case HeadingSource::kEncoders:
      break;
    case HeadingSource::kGyrodometry:
      if (have_rate_ && dt > 0 && std::abs(gyro_turn_ - turn_enc) > options_.threshold_rad_s * dt) {
        turn = gyro_turn_;
        ++gyro_steps_;
      }
      break;
    case HeadingSource::kComplementary:
      if (have_rate_) turn = options_.gyro_weight * gyro_turn_ + (1.0 - options_.gyro_weight) * turn_enc;
      break;
    case HeadingSource::kImuYaw:
      if (have_yaw_) turn = yaw_turn_;
      break;
  }
  gyro_turn_ = yaw_turn_ = 0.0;
  const double mid = pose_.theta + 0.5 * turn;
  pose_.x += ds * std::cos(mid);
  pose_.y += ds * std::sin(mid);
  pose_.theta = WrapAngle(pose_.theta + turn);
  return pose_;
}

}  // namespace mbot::motion
