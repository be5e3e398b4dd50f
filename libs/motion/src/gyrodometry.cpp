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
  WheelStep step = wheels_.Step(left_ticks, right_ticks);
  const double dt = (t_us - last_enc_us_) * 1e-6;
  last_enc_us_ = t_us;
  if (!started_) {  // the first reading only sets the references
    started_ = true;
    gyro_turn_ = yaw_turn_ = 0.0;
    return wheels_.pose();
  }
  moved_ = moved_ || step.distance_m != 0.0 || step.turn_rad != 0.0;
  switch (options_.heading) {
    case HeadingSource::kEncoders: break;
    case HeadingSource::kGyrodometry:
      if (have_rate_ && dt > 0 && std::abs(gyro_turn_ - step.turn_rad) > options_.threshold_rad_s * dt) {
        step.turn_rad = gyro_turn_;
        ++gyro_steps_;
      }
      break;
    case HeadingSource::kComplementary:
      if (have_rate_) step.turn_rad = options_.gyro_weight * gyro_turn_ + (1.0 - options_.gyro_weight) * step.turn_rad;
      break;
    case HeadingSource::kImuYaw:
      if (have_yaw_) step.turn_rad = yaw_turn_;
      break;
  }
  gyro_turn_ = yaw_turn_ = 0.0;
  return wheels_.Apply(step);
}

}  // namespace mbot::motion
