// The robot's wheel constants, defaulting to the classic MBot (the mbot_classic firmware's
// GEAR_RATIO 78, ENCODER_RES 48, WHEEL_DIAMETER 0.0837 m, WHEEL_BASE 0.15571 m).
#pragma once

#include "mbot/motion/wheel_odometry.hpp"

namespace mbot::motion {

struct RobotGeometry {
  double wheel_radius_m = 0.0837 / 2.0;
  double base_radius_m = 0.07786;    // half the distance between the wheels' contact points
  double gear_ratio = 78.0;          // motor turns per wheel turn
  double encoder_resolution = 48.0;  // counts per motor revolution
  int left_encoder_polarity = 1;     // +1: the encoder counts up when the wheel turns forward
  int right_encoder_polarity = 1;

  double RadPerTick() const { return 2.0 * 3.14159265358979323846 / (gear_ratio * encoder_resolution); }
  double MetresPerTick() const { return RadPerTick() * wheel_radius_m; }
  // Dead-reckoning constants: metres per tick signed with each encoder's polarity, base 2·radius.
  WheelOdometryOptions Odometry() const {
    return {left_encoder_polarity * MetresPerTick(), right_encoder_polarity * MetresPerTick(), 2.0 * base_radius_m};
  }
};

}  // namespace mbot::motion
