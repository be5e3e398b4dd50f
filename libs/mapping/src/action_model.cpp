#include "mbot/mapping/action_model.hpp"

#include <algorithm>
#include <cmath>

#include "mbot/mapping/random.hpp"

namespace mbot::mapping {

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
