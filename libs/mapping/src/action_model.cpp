#include "mbot/mapping/action_model.hpp"

#include <algorithm>
#include <cmath>

#include "mbot/mapping/random.hpp"

namespace mbot::mapping {

OdometryStep ActionModel::StepBetween(const motion::Pose2D& from, const motion::Pose2D& to) {
  OdometryStep s;
  const double dx = to.x - from.x, dy = to.y - from.y;
  s.trans = std::hypot(dx, dy);
  s.rot1 = s.trans > 1e-6 ? motion::WrapAngle(std::atan2(dy, dx) - from.theta) : 0.0;
  if (std::abs(s.rot1) > M_PI / 2) {  // driving backwards
    s.rot1 = motion::WrapAngle(s.rot1 + M_PI);
    s.trans = -s.trans;
  }
  s.rot2 = motion::WrapAngle(to.theta - from.theta - s.rot1);
  return s;
}

bool ActionModel::Moved(const motion::Pose2D& from, const motion::Pose2D& to) const {
  return std::hypot(to.x - from.x, to.y - from.y) >= options_.min_trans_m ||
         std::abs(motion::WrapAngle(to.theta - from.theta)) >= options_.min_rot_rad;
}

motion::Pose2D ActionModel::Sample(const motion::Pose2D& p, const OdometryStep& step, uint64_t key) const {
  CounterRng rng(key);
  const double s1 = std::max(std::sqrt(options_.k1 * std::abs(step.rot1)), options_.min_sigma_rot_rad);
  const double st = std::max(std::sqrt(options_.k2 * std::abs(step.trans)), options_.min_sigma_trans_m);
  const double s2 = std::max(std::sqrt(options_.k1 * std::abs(step.rot2)), options_.min_sigma_rot_rad);
  const double rot1 = step.rot1 + s1 * rng.Normal();
  const double trans = step.trans + st * rng.Normal();
  const double rot2 = step.rot2 + s2 * rng.Normal();
  const double heading = p.theta + rot1;
  return {p.x + trans * std::cos(heading), p.y + trans * std::sin(heading), motion::WrapAngle(heading + rot2)};
}

}  // namespace mbot::mapping
