// Odometry made worse on purpose, for robustness tests of the localization: Gaussian noise on each
// step (proportional to its length and turn), glitches (jumps at a fixed period that stay), and a
// kidnapping — from a given time on, every pose is offset by a fixed jump, as if the robot had been
// carried away. Seeded: the same seed gives the same noise.
#pragma once

#include <cstdint>
#include <random>

#include "mbot/motion/pose2d.hpp"

namespace mbot::motion {

struct OdometryPerturbationOptions {
  double noise_trans = 0.0;   // sigma of x and y per metre of each step
  double noise_rot = 0.0;     // sigma of the heading per radian and metre of each step
  double kidnap_at_s = -1.0;  // from this long after the first pose on, poses are offset (< 0: never)
  Pose2D kidnap_offset{1.0, 0.0, M_PI / 2};
  // Glitches: every `jump_every_s` of the stream (0: never) the odometry jumps by up to `jump_max_m`
  // in a random direction (uniform in length) and up to ±`jump_max_rad`, and stays jumped, as a
  // wheel-odometry glitch does between two scans.
  double jump_every_s = 0.0;
  double jump_max_m = 1.0, jump_max_rad = 0.0;
};

class OdometryPerturbation {
 public:
  OdometryPerturbation(const OdometryPerturbationOptions& options, uint64_t seed);
  // The perturbed pose for the raw odometry pose `raw` at `t_us`; `start_us` is the stream's first
  // time (the kidnapping's clock). Identity when no perturbation is configured.
  Pose2D Apply(int64_t t_us, int64_t start_us, const Pose2D& raw);
  // When the kidnapping happened (the first pose it offset), or -1.
  int64_t kidnapped_at_us() const { return kidnap_us_; }
  int jumps() const { return jumps_; }

 private:
  OdometryPerturbationOptions o_;
  std::mt19937_64 rng_;
  bool first_ = true;
  Pose2D last_raw_, noisy_;
  int64_t kidnap_us_ = -1;
  Pose2D jumped_;  // the glitches so far, in the odometry's frame
  int jumps_ = 0;
};

}  // namespace mbot::motion
