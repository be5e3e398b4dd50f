// Gyro-fused odometry on a synthetic drive: a turn during which the left wheel slips (its encoder
// counts turns the ground never saw). The encoders get the heading wrong; the gyro does not.
#include "mbot/motion/gyrodometry.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace mbot::motion {
namespace {

// Drives 1 s straight, turns 90° in place over 1 s (left wheel slipping: 30 % extra counts), drives
// 1 s straight; encoders and gyro (with a 0.01 rad/s bias) at 50 Hz. Returns the final pose.
Pose2D Drive(HeadingSource heading, int* gyro_steps = nullptr) {
  const WheelOdometryOptions wheels{1e-4, 1e-4, 0.2};
  GyrodometryOptions o;
  o.heading = heading;
  Gyrodometry g(wheels, o);
  const double dt = 0.02, bias = 0.01;
  double left = 0, right = 0, yaw = 0;
  int64_t t = 0;
  for (int k = 0; k <= 200; ++k, t += 20000) {  // 1 s standing still first: the bias estimate
    double v = 0, w = 0, slip = 1.0;
    if (k > 50 && k <= 100) v = 0.2;
    if (k > 100 && k <= 150) w = M_PI / 2, slip = 1.3;
    if (k > 150) v = 0.2;
    g.AddImu(t, w + bias, yaw, true);
    yaw = WrapAngle(yaw + w * dt);
    left += (v - w * 0.1) * dt / 1e-4 * slip;
    right += (v + w * 0.1) * dt / 1e-4;
    g.AddEncoders(t, std::llround(left), std::llround(right));
  }
  if (gyro_steps) *gyro_steps = g.gyro_steps();
  return g.pose();
}

TEST(Gyrodometry, GyroFixesTheHeadingASlippingWheelGetsWrong) {
  const Pose2D truth{0.2, 0.2, M_PI / 2};
  const Pose2D enc = Drive(HeadingSource::kEncoders);
  int gyro_steps = 0;
  const Pose2D fused = Drive(HeadingSource::kGyrodometry, &gyro_steps);
  const Pose2D imu = Drive(HeadingSource::kImuYaw);
  EXPECT_GT(std::abs(WrapAngle(enc.theta - truth.theta)), 0.2);  // the slip costs the encoders > 11°
  EXPECT_LT(std::abs(WrapAngle(fused.theta - truth.theta)), 0.02);
  EXPECT_LT(std::abs(WrapAngle(imu.theta - truth.theta)), 0.02);
  // The slip also moves the midpoint by half its extra counts: 0.024 m backwards during the turn,
  // at a mean heading of 45°. The gyro cannot fix that part.
  const double slip_back = 0.3 * 0.1 * M_PI / 2 / 2 * std::cos(M_PI / 4);
  EXPECT_NEAR(fused.x, truth.x - slip_back, 0.005);
  EXPECT_NEAR(fused.y, truth.y - slip_back, 0.005);
  EXPECT_GE(gyro_steps, 40);  // the turn's steps, not the straight ones
  EXPECT_LE(gyro_steps, 60);
}

}  // namespace
}  // namespace mbot::motion
