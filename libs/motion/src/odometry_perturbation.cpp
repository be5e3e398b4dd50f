#include "mbot/motion/odometry_perturbation.hpp"

#include <cmath>

namespace mbot::motion {

OdometryPerturbation::OdometryPerturbation(const OdometryPerturbationOptions& options, uint64_t seed)
    : o_(options), rng_(seed ^ 0x6f646f6dULL) {}

Pose2D OdometryPerturbation::Apply(int64_t t_us, int64_t start_us, const Pose2D& raw) {
  Pose2D out = raw;
  if (o_.noise_trans > 0 || o_.noise_rot > 0) {
    if (!first_) {
      const Pose2D d = last_raw_.Inverse().Compose(raw);
      const double ds = std::hypot(d.x, d.y);
      std::normal_distribution<double> n(0.0, 1.0);
      const Pose2D noisy{d.x + o_.noise_trans * ds * n(rng_), d.y + o_.noise_trans * ds * n(rng_),
                         d.theta + o_.noise_rot * (std::abs(d.theta) + ds) * n(rng_)};
      out = noisy_.Compose(noisy);
    }
    noisy_ = out;
  }
  first_ = false;
  last_raw_ = raw;
  if (o_.jump_every_s > 0 && start_us >= 0) {
    const int due = static_cast<int>((t_us - start_us) / (o_.jump_every_s * 1e6));
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (; jumps_ < due; ++jumps_) {
      const double length = o_.jump_max_m * u(rng_), direction = 2 * M_PI * u(rng_);
      const Pose2D jump{length * std::cos(direction), length * std::sin(direction),
                        o_.jump_max_rad * (2 * u(rng_) - 1)};
      // Moved by `jump` and turned about where the odometry has the robot now.
      const Pose2D at = jumped_.Compose(out);
      jumped_ = Pose2D{at.x + jump.x, at.y + jump.y, jump.theta}.Compose(Pose2D{-at.x, -at.y, 0}).Compose(jumped_);
    }
    out = jumped_.Compose(out);
  }
  if (o_.kidnap_at_s >= 0 && start_us >= 0 && t_us - start_us >= o_.kidnap_at_s * 1e6) {
    if (kidnap_us_ < 0) kidnap_us_ = t_us;
    out = o_.kidnap_offset.Compose(out);
  }
  return out;
}

}  // namespace mbot::motion
