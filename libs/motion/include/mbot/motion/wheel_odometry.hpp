// Dead reckoning of a differential-drive robot from cumulative encoder ticks (midpoint
// integration). The Motion issue adds the gyro fusion; the SLAM replay needs it for logs that carry
// encoders but no odometry channel (the Maebot log).
#pragma once

#include <cstdint>

#include "mbot/motion/pose2d.hpp"

namespace mbot::motion {

struct WheelOdometryOptions {
  double left_m_per_tick = 0.0;  // signed: the polarity is in the sign
  double right_m_per_tick = 0.0;
  double wheel_base_m = 0.0;  // distance between the wheels' contact points
};

// What the wheels say the robot did between two encoder readings.
struct WheelStep {
  double distance_m = 0.0;  // of the midpoint between the wheels, forward positive
  double turn_rad = 0.0;    // counter-clockwise
};

class WheelOdometry {
 public:
  explicit WheelOdometry(const WheelOdometryOptions& options);
  // Cumulative tick counts; the first call only sets the reference. Returns the pose.
  const Pose2D& Update(int64_t left_ticks, int64_t right_ticks) { return Apply(Step(left_ticks, right_ticks)); }
  // The two halves of Update, for callers that replace the turn (gyro fusion): the step since the
  // last reading (zero on the first), and the pose moved by a step (midpoint integration).
  WheelStep Step(int64_t left_ticks, int64_t right_ticks);
  const Pose2D& Apply(const WheelStep& step);
  const Pose2D& pose() const { return pose_; }

 private:
  WheelOdometryOptions options_;
  Pose2D pose_;
  bool started_ = false;
  int64_t left_ = 0, right_ = 0;
};

}  // namespace mbot::motion
