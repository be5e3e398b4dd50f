// Planar poses: the message vocabulary's Pose2D (libs/msgs), and the operations on poses the
// algorithms share (interpolation, odometry steps, timed series).
#pragma once

#include <cstdint>
#include <vector>

#include "mbot/msgs/pose2d.hpp"

namespace mbot::motion {

using msgs::Pose2D;
using msgs::WrapAngle;

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
