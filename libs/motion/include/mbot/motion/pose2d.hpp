// Planar poses (x, y in metres, theta in radians) and the SE(2) operations the stack shares.
#pragma once

#include <cstdint>
#include <vector>

namespace mbot::motion {

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

// Linear interpolation of position and shortest-arc interpolation of heading; s in [0, 1].
Pose2D Interpolate(const Pose2D& a, const Pose2D& b, double s);

// An odometry step split as the odometry motion model does (Thrun et al. §5.4): turn rot1 towards
// the destination, drive trans, turn rot2. A backward step keeps |rot1| ≤ π/2 and gets a negative
// trans; a step shorter than 1 µm is all rotation (rot1 = 0).
struct OdometryStep {
  double rot1 = 0, trans = 0, rot2 = 0;
};
OdometryStep OdometryStepBetween(const Pose2D& from, const Pose2D& to);

struct TimedPose {
  int64_t t_us = 0;
  Pose2D pose;
};

// Pose at time t_us from a time-sorted series, interpolated between its neighbours. Returns false
// (and leaves `out` alone) when t_us lies outside the series by more than `max_gap_us` or the
// neighbours are further than `max_gap_us` apart.
bool InterpolateAt(const std::vector<TimedPose>& series, int64_t t_us, int64_t max_gap_us, Pose2D* out);

}  // namespace mbot::motion
