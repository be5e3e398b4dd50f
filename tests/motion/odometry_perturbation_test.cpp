// Odometry perturbation (noise and kidnapping) and the trajectory evaluation.
#include "mbot/motion/odometry_perturbation.hpp"

#include <gtest/gtest.h>

#include "mbot/motion/trajectory_error.hpp"

namespace mbot::motion {
namespace {

TEST(OdometryPerturbation, IdentityWithoutOptionsAndAKidnappingOffsetsFromItsTime) {
  OdometryPerturbation none({}, 1);
  EXPECT_DOUBLE_EQ(none.Apply(0, 0, {1, 2, 0.3}).x, 1.0);
  OdometryPerturbationOptions o;
  o.kidnap_at_s = 2.0;
  o.kidnap_offset = {1.0, 0.0, 0.0};
  OdometryPerturbation k(o, 1);
  EXPECT_DOUBLE_EQ(k.Apply(1'000'000, 0, {0.5, 0, 0}).x, 0.5);
  EXPECT_EQ(k.kidnapped_at_us(), -1);
  EXPECT_DOUBLE_EQ(k.Apply(2'000'000, 0, {0.5, 0, 0}).x, 1.5);
  EXPECT_EQ(k.kidnapped_at_us(), 2'000'000);
}

TEST(OdometryPerturbation, NoiseGrowsWithDistanceAndIsSeeded) {
  OdometryPerturbationOptions o;
  o.noise_trans = 0.1;
  o.noise_rot = 0.1;
  auto drive = [&](uint64_t seed) {
    OdometryPerturbation p(o, seed);
    Pose2D out;
    for (int i = 0; i <= 100; ++i) out = p.Apply(i * 20'000, 0, {0.01 * i, 0, 0});
    return out;
  };
  const Pose2D a = drive(3), b = drive(3), c = drive(4);
  EXPECT_DOUBLE_EQ(a.x, b.x);
  EXPECT_NE(a.x, c.x);
  EXPECT_GT(std::hypot(a.x - 1.0, a.y) + std::abs(a.theta), 1e-4);  // perturbed
  EXPECT_LT(std::hypot(a.x - 1.0, a.y), 0.5);                       // but not wildly
}

TEST(TrajectoryErrors, AnEstimateOffsetByARigidMotionIsPerfectOnceAligned) {
  std::vector<Pose2D> truth, est;
  const Pose2D offset{0.5, -0.2, 0.3};
  for (int i = 0; i < 20; ++i) {
    truth.push_back({0.1 * i, 0.05 * i * i * 0.01, 0.02 * i});
    est.push_back(offset.Compose(truth.back()));
  }
  const TrajectoryErrors e = EvaluateTrajectory(est, truth);
  EXPECT_LT(e.aligned.xy.rmse, 1e-9);
  EXPECT_LT(e.anchored.xy.rmse, 1e-9);
  EXPECT_GT(e.unaligned.xy.rmse, 0.3);
  EXPECT_EQ(e.aligned.samples, 20);
}

}  // namespace
}  // namespace mbot::motion
