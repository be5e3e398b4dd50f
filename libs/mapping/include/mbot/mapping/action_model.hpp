// The odometry motion model (Thrun et al., Probabilistic Robotics §5.4) as the botlab uses it: the
// odometry step is split into rot1, trans, rot2, and each particle moves by a noisy copy with
// σ_rot = sqrt(k1·|rot|), σ_trans = sqrt(k2·|trans|), never below small floors, so a robot that
// barely moved still diffuses a little.
#pragma once

#include <cstdint>

#include "mbot/motion/pose2d.hpp"

namespace mbot::mapping {

struct ActionModelOptions {
  double k1 = 0.005;  // rotation noise [rad per rad]
  double k2 = 0.005;  // translation noise [m per m]
  double min_sigma_trans_m = 0.002;
  double min_sigma_rot_rad = 0.002;
  // The filter updates only once odometry moved at least this far or turned this much.
  double min_trans_m = 0.01;
  double min_rot_rad = 0.02;
};

using motion::OdometryStep;

class ActionModel {
 public:
  explicit ActionModel(const ActionModelOptions& options) : options_(options) {}
  // (rot1, trans, rot2) from one odometry pose to the next (motion::OdometryStepBetween).
  static OdometryStep StepBetween(const motion::Pose2D& from, const motion::Pose2D& to) {
    return motion::OdometryStepBetween(from, to);
  }
  // Whether the step from `from` to `to` is large enough to update the filter.
  bool Moved(const motion::Pose2D& from, const motion::Pose2D& to) const;
  // The standard deviations of rot1, trans and rot2 for one step (the same for every particle).
  struct StepNoise {
    double rot1, trans, rot2;
  };
  StepNoise NoiseOf(const OdometryStep& step) const;
  // A sample of the particle's pose after `step`, drawn from the random stream `key`.
  motion::Pose2D Sample(const motion::Pose2D& particle, const OdometryStep& step, uint64_t key) const {
    return Sample(particle, step, NoiseOf(step), key);
  }
  // The same with the step's noise worked out once for all particles.
  motion::Pose2D Sample(const motion::Pose2D& particle, const OdometryStep& step, const StepNoise& noise,
                        uint64_t key) const;
  const ActionModelOptions& options() const { return options_; }

 private:
  ActionModelOptions options_;
};

}  // namespace mbot::mapping
