#include "mbot/mapping/action_model.hpp"

#include <algorithm>
#include <cmath>

#include "mbot/mapping/random.hpp"

namespace mbot::mapping {

bool ActionModel::Moved(const motion::Pose2D& from, const motion::Pose2D& to) const {
  return std::hypot(to.x - from.x, to.y - from.y) >= options_.min_trans_m ||
         std::abs(motion::WrapAngle(to.theta - from.theta)) >= options_.min_rot_rad;
}

ActionModel::StepNoise ActionModel::NoiseOf(const OdometryStep& step) const {
  return {std::max(std::sqrt(options_.k1 * std::abs(step.rot1)), options_.min_sigma_rot_rad),
          std::max(std::sqrt(options_.k2 * std::abs(step.trans)), options_.min_sigma_trans_m),
          std::max(std::sqrt(options_.k1 * std::abs(step.rot2)), options_.min_sigma_rot_rad)};
}

motion::Pose2D ActionModel::Sample(const motion::Pose2D& p, const OdometryStep& step, const StepNoise& noise,
                                   uint64_t key) const {
  CounterRng rng(key);
  const double rot1 = step.rot1 + noise.rot1 * rng.Normal();
  const double trans = step.trans + noise.trans * rng.Normal();
  const double rot2 = step.rot2 + noise.rot2 * rng.Normal();
  const double heading = p.theta + rot1;
  return {p.x + trans * std::cos(heading), p.y + trans * std::sin(heading), motion::WrapAngle(heading + rot2)};
}

}  // namespace mbot::mapping
