#include "mbot/motion/pose2d.hpp"

#include <algorithm>
#include <cmath>

namespace mbot::motion {

Pose2D Interpolate(const Pose2D& a, const Pose2D& b, double s) {
  return {a.x + s * (b.x - a.x), a.y + s * (b.y - a.y), WrapAngle(a.theta + s * WrapAngle(b.theta - a.theta))};
}

OdometryStep OdometryStepBetween(const Pose2D& from, const Pose2D& to) {
  OdometryStep s;
  const double dx = to.x - from.x, dy = to.y - from.y;
  s.trans = std::hypot(dx, dy);
  s.rot1 = s.trans > 1e-6 ? WrapAngle(std::atan2(dy, dx) - from.theta) : 0.0;
  if (std::abs(s.rot1) > M_PI / 2) {  // driving backwards
    s.rot1 = WrapAngle(s.rot1 + M_PI);
    s.trans = -s.trans;
  }
  s.rot2 = WrapAngle(to.theta - from.theta - s.rot1);
  return s;
}

bool InterpolateAt(const std::vector<TimedPose>& series, int64_t t_us, int64_t max_gap_us, Pose2D* out) {
  if (series.empty()) return false;
  auto it =
      std::lower_bound(series.begin(), series.end(), t_us, [](const TimedPose& p, int64_t t) { return p.t_us < t; });
  if (it == series.end()) {
    if (t_us - series.back().t_us > max_gap_us) return false;
    *out = series.back().pose;
    return true;
  }
  if (it == series.begin() || it->t_us == t_us) {
    if (it->t_us - t_us > max_gap_us) return false;
    *out = it->pose;
    return true;
  }
  const TimedPose& b = *it;
  const TimedPose& a = *(it - 1);
  if (b.t_us - a.t_us > max_gap_us) return false;
  *out = Interpolate(a.pose, b.pose, double(t_us - a.t_us) / double(b.t_us - a.t_us));
  return true;
}

}  // namespace mbot::motion
