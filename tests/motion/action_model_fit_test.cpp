#include "mbot/motion/action_model_fit.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace mbot::motion {
namespace {

struct Log {
  std::vector<Pose2D> odometry, truth;
};

// The pose after driving (rot1, trans, rot2) from `p`.
Pose2D Apply(const Pose2D& p, double rot1, double trans, double rot2) {
  const double heading = p.theta + rot1;
  return {p.x + trans * std::cos(heading), p.y + trans * std::sin(heading), WrapAngle(heading + rot2)};
}

// A wandering odometry path of `windows` steps mixing straight drives, arcs, reversing, turns on
// the spot and stops, each spread over `window_steps` samples. Each window's true step is its
// odometry step plus the model's noise, σ² = k·|x| + floor², with σ evaluated on the odometry
// step as the filter does (so true − odometry follows the fitted model exactly).
Log MakeLog(int windows, int window_steps, double k1, double k2, uint32_t seed) {
  const ActionModelFitOptions defaults;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> n(0.0, 1.0);
  auto sigma = [](double k, double x, double floor) { return std::sqrt(k * std::abs(x) + floor * floor); };
  Log log;
  Pose2D odo{0, 0, 0}, tru{0.5, -0.2, 0.3};  // the frames need not agree
  log.odometry.push_back(odo);
  log.truth.push_back(tru);
  for (int i = 0; i < windows; ++i) {
    const double mode = u(rng), sign = u(rng) < 0.5 ? -1.0 : 1.0;
    double rot1 = 0, trans = 0, rot2 = 0;
    if (mode < 0.35) {  // straight-ish drive
      rot1 = 0.05 * n(rng), trans = 0.1 + 0.2 * u(rng), rot2 = 0.05 * n(rng);
    } else if (mode < 0.65) {  // arc
      const double turn = sign * (0.2 + 0.6 * u(rng));
      rot1 = rot2 = turn / 2, trans = 0.1 + 0.2 * u(rng);
    } else if (mode < 0.75) {  // reversing
      rot1 = 0.2 * n(rng), trans = -(0.05 + 0.15 * u(rng)), rot2 = 0.2 * n(rng);
    } else if (mode < 0.95) {  // turn on the spot
      rot2 = sign * (0.3 + 1.2 * u(rng));
    }  // else: stop
    const Pose2D odo_next = Apply(odo, rot1, trans, rot2);
    Pose2D tru_next = tru;
    if (mode < 0.95) {
      tru_next = Apply(tru, rot1 + sigma(k1, rot1, defaults.min_sigma_rot_rad) * n(rng),
                       trans + sigma(k2, trans, defaults.min_sigma_trans_m) * n(rng),
                       rot2 + sigma(k1, rot2, defaults.min_sigma_rot_rad) * n(rng));
    }
    for (int j = 1; j <= window_steps; ++j) {  // intermediate samples do not enter the fit
      const double s = static_cast<double>(j) / window_steps;
      log.odometry.push_back(Interpolate(odo, odo_next, s));
      log.truth.push_back(Interpolate(tru, tru_next, s));
    }
    odo = odo_next;
    tru = tru_next;
  }
  return log;
}

void ExpectRecovers(double k1, double k2, uint32_t seed) {
  const ActionModelFitOptions options;
  const Log log = MakeLog(3000, options.window_steps, k1, k2, seed);
  const ActionModelFit fit = FitActionModel(log.odometry, log.truth, options);
  ASSERT_TRUE(fit.converged) << fit.message;
  ::testing::Test::RecordProperty("k1_fit_std", std::to_string(fit.k1) + " " + std::to_string(fit.k1_std));
  ::testing::Test::RecordProperty("k2_fit_std", std::to_string(fit.k2) + " " + std::to_string(fit.k2_std));
  EXPECT_TRUE(fit.message.empty()) << fit.message;
  EXPECT_GT(fit.windows_used, 2700);
  EXPECT_GT(fit.windows_skipped, 100);
  EXPECT_NEAR(fit.k1, k1, 0.1 * k1);
  EXPECT_NEAR(fit.k2, k2, 0.1 * k2);
  EXPECT_GT(fit.k1_std, 0);
  EXPECT_LT(fit.k1_std, fit.k1);
  EXPECT_GT(fit.k2_std, 0);
  EXPECT_LT(fit.k2_std, fit.k2);
  // The std is a calibrated confidence, not just a small number.
  EXPECT_LT(std::abs(fit.k1 - k1), 4 * fit.k1_std);
  EXPECT_LT(std::abs(fit.k2 - k2), 4 * fit.k2_std);
  EXPECT_TRUE(std::isfinite(fit.nll));
}

TEST(ActionModelFitTest, RecoversSeedReportNoise) { ExpectRecovers(0.001, 0.001, 1); }

TEST(ActionModelFitTest, RecoversUnequalNoise) { ExpectRecovers(0.0025, 0.0005, 2); }

TEST(ActionModelFitTest, StartingPointDoesNotMatter) {
  const Log log = MakeLog(3000, 10, 0.0025, 0.0005, 3);
  ActionModelFitOptions far;
  far.initial_k1 = 1.0;
  far.initial_k2 = 1e-6;
  const ActionModelFit a = FitActionModel(log.odometry, log.truth, ActionModelFitOptions{});
  const ActionModelFit b = FitActionModel(log.odometry, log.truth, far);
  ASSERT_TRUE(a.converged && b.converged) << a.message << " | " << b.message;
  EXPECT_NEAR(a.k1, b.k1, 1e-4 * a.k1);
  EXPECT_NEAR(a.k2, b.k2, 1e-4 * a.k2);
}

TEST(ActionModelFitTest, NoMotionIsNotConverged) {
  const std::vector<Pose2D> still(101, Pose2D{1.0, 2.0, 0.5});
  const ActionModelFit fit = FitActionModel(still, still, ActionModelFitOptions{});
  EXPECT_FALSE(fit.converged);
  EXPECT_EQ(fit.windows_used, 0);
  EXPECT_EQ(fit.windows_skipped, 10);
  EXPECT_NE(fit.message.find("no usable window"), std::string::npos) << fit.message;
}

TEST(ActionModelFitTest, BadInputIsNotConverged) {
  const Log log = MakeLog(20, 10, 0.001, 0.001, 4);
  std::vector<Pose2D> shorter = log.truth;
  shorter.pop_back();
  ActionModelFit fit = FitActionModel(log.odometry, shorter, ActionModelFitOptions{});
  EXPECT_FALSE(fit.converged);
  EXPECT_NE(fit.message.find("differ in length"), std::string::npos) << fit.message;

  fit = FitActionModel({}, {}, ActionModelFitOptions{});
  EXPECT_FALSE(fit.converged);
  EXPECT_NE(fit.message.find("too short"), std::string::npos) << fit.message;

  ActionModelFitOptions bad;
  bad.window_steps = 0;
  fit = FitActionModel(log.odometry, log.truth, bad);
  EXPECT_FALSE(fit.converged);
  EXPECT_NE(fit.message.find("invalid options"), std::string::npos) << fit.message;
}

TEST(ActionModelFitTest, OnlyTurningLeavesK2Unobservable) {
  std::vector<Pose2D> odo, tru;
  for (int i = 0; i <= 200; ++i) {
    odo.push_back({0, 0, WrapAngle(0.05 * i)});
    tru.push_back({0, 0, WrapAngle(0.051 * i)});
  }
  const ActionModelFit fit = FitActionModel(odo, tru, ActionModelFitOptions{});
  EXPECT_FALSE(fit.converged);
  EXPECT_EQ(fit.windows_used, 20);
  EXPECT_NE(fit.message.find("k2 is not observable"), std::string::npos) << fit.message;
}

TEST(ActionModelFitTest, FewWindowsAreFlagged) {
  const Log log = MakeLog(6, 10, 0.001, 0.001, 5);
  const ActionModelFit fit = FitActionModel(log.odometry, log.truth, ActionModelFitOptions{});
  EXPECT_LT(fit.windows_used, 10);
  EXPECT_NE(fit.message.find("estimates are rough"), std::string::npos) << fit.message;
}

}  // namespace
}  // namespace mbot::motion

namespace mbot::motion {
namespace {

// A burst: the third sample arrived 0.8 s late; on its stamp it goes back between its neighbours.
TEST(PlaceOnStamps, LateSamplesGoToTheirStampsOnTheLogClock) {
  std::vector<TimedPose> s = {
      {1'000'000, {0, 0, 0}}, {1'100'000, {1, 0, 0}}, {2'000'000, {2, 0, 0}}, {1'300'000, {3, 0, 0}}};
  const std::vector<int64_t> stamps = {500'000, 600'000, 700'000, 800'000};  // the robot's clock
  EXPECT_NEAR(PlaceOnStamps(&s, stamps), 0.8, 1e-9);
  ASSERT_EQ(s.size(), 4u);
  EXPECT_EQ(s[0].t_us, 1'000'000);
  EXPECT_EQ(s[2].t_us, 1'200'000);  // the late one, at its stamp + 0.5 s
  EXPECT_EQ(s[2].pose.x, 2);
  std::vector<TimedPose> unstamped = {{1, {}}, {2, {}}};
  EXPECT_EQ(PlaceOnStamps(&unstamped, {0, 5}), -1);
  EXPECT_EQ(unstamped[0].t_us, 1);
}

}  // namespace
}  // namespace mbot::motion
