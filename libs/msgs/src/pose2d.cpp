#include "mbot/msgs/pose2d.hpp"

#include <cmath>

namespace mbot::msgs {

double WrapAngle(double a) {
  if (a > -M_PI && a <= M_PI) return a;  // already wrapped: returned as is (and without an fmod)
  a = std::fmod(a + M_PI, 2.0 * M_PI);
  if (a <= 0.0) a += 2.0 * M_PI;
  return a - M_PI;
}

Pose2D Pose2D::Compose(const Pose2D& o) const {
  const double c = std::cos(theta), s = std::sin(theta);
  return {x + c * o.x - s * o.y, y + s * o.x + c * o.y, WrapAngle(theta + o.theta)};
}

Pose2D Pose2D::Inverse() const {
  const double c = std::cos(theta), s = std::sin(theta);
  return {-c * x - s * y, s * x - c * y, WrapAngle(-theta)};
}

}  // namespace mbot::msgs
