// The planar pose every message and module shares (x, y in metres, theta in radians) and its SE(2)
// group operations. Interpolation, odometry steps and timed series stay in libs/motion.
#pragma once

namespace mbot::msgs {

// Wraps an angle to (-pi, pi].
double WrapAngle(double a);

struct Pose2D {
  double x = 0.0;
  double y = 0.0;
  double theta = 0.0;

  // this ⊕ other: `other` expressed in this pose's frame, mapped to the world frame.
  Pose2D Compose(const Pose2D& other) const;
  // The pose that composes with this one to the identity.
  Pose2D Inverse() const;
};

}  // namespace mbot::msgs
