// Wheel odometry with the IMU's heading fused in. Encoders measure distance well but heading
// poorly (wheel slip, an uncertain wheel base); the gyro measures heading change well over short
// spans. Three ways to combine them per encoder step:
//  - encoders: the wheels alone (the baseline);
//  - gyrodometry (Borenstein & Feng 1996): trust the gyro's heading change when it disagrees with
//    the encoders' by more than a threshold rate, else the encoders';
//  - complementary: a fixed blend of the two heading changes;
//  - imu_yaw: the IMU's own yaw angle differences replace the encoders' heading change (the seed
//    report's "updated odometry").
// Gyro rates are integrated between encoder messages; a constant bias is estimated while the
// wheels stand still at the start.
#pragma once

#include <cstdint>

#include "mbot/motion/pose2d.hpp"
#include "mbot/motion/wheel_odometry.hpp"

namespace mbot::motion {

enum class HeadingSource { kEncoders, kGyrodometry, kComplementary, kImuYaw };

struct GyrodometryOptions {
  HeadingSource heading = HeadingSource::kGyrodometry;
  double threshold_rad_s = 0.1;  // gyrodometry: use the gyro when the rates differ by more than this (best of 0.02–0.2
                                 // on sweep_drive_square)
  double gyro_weight = 0.98;  // complementary: share of the gyro's heading change
  double gyro_scale = 1.0;    // multiplies the gyro rate (calibration)
  bool estimate_bias = true;  // average the gyro while the wheels have not moved yet
};

class Gyrodometry {
 public:
  Gyrodometry(const WheelOdometryOptions& wheels, const GyrodometryOptions& options);
  // An IMU sample: yaw rate [rad/s, counter-clockwise] and, when the IMU gives one, its yaw angle.
  void AddImu(int64_t t_us, double yaw_rate_rad_s, double yaw_rad, bool has_yaw);
  // Cumulative encoder ticks; the first call sets the reference. Returns the pose.
  const Pose2D& AddEncoders(int64_t t_us, int64_t left_ticks, int64_t right_ticks);
  const Pose2D& pose() const { return wheels_.pose(); }
  double gyro_bias_rad_s() const { return bias_count_ ? bias_sum_ / bias_count_ : 0.0; }
  int gyro_steps() const { return gyro_steps_; }  // encoder steps whose heading came from the gyro

 private:
  WheelOdometry wheels_;
  GyrodometryOptions options_;
  bool started_ = false, moved_ = false;
  int64_t last_enc_us_ = 0;
  // Gyro integration since the last encoder step.
  bool have_rate_ = false;
  int64_t last_imu_us_ = 0;
  double last_rate_ = 0.0, gyro_turn_ = 0.0;
  double bias_sum_ = 0.0;
  int bias_count_ = 0;
  // IMU yaw.
  bool have_yaw_ = false;
  double last_yaw_ = 0.0, yaw_turn_ = 0.0;
  int gyro_steps_ = 0;
};

}  // namespace mbot::motion
