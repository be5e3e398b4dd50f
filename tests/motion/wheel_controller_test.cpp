// The wheel-speed controller on a first-order motor: step response without oscillation, and no
// wind-up after a command the motor cannot reach.
#include "mbot/motion/wheel_controller.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace mbot::motion {
namespace {

// A motor whose steady-state speed follows `truth` and which reaches it with time constant τ.
struct FirstOrderMotor {
  WheelCalibration truth;
  double tau_s = 0.1;
  double speed = 0.0;
  double Step(double duty, double dt) {
    speed += (truth.SpeedFor(duty) - speed) * (1.0 - std::exp(-dt / tau_s));
    return speed;
  }
};

struct SpeedTrace {
  std::vector<double> target, speed;
};

// Drives the left wheel alone (ω chosen so the right target is 0 is not needed: both wheels run
// the same command) and records the left target and speed.
SpeedTrace Simulate(const WheelControllerOptions& o, const MotorCalibration& model, const WheelCalibration& plant,
                    const std::vector<std::pair<double, double>>& v_schedule, double seconds) {
  WheelSpeedController c(o, RobotGeometry{}, model);
  FirstOrderMotor left{plant}, right{plant};
  SpeedTrace r;
  for (int k = 0; k * o.dt_s < seconds; ++k) {
    double v = 0;
    for (const auto& [from_s, value] : v_schedule)
      if (k * o.dt_s >= from_s) v = value;
    const WheelDuties d = c.Update(v, 0.0, left.speed, right.speed);
    left.Step(d.left, o.dt_s);
    right.Step(d.right, o.dt_s);
    r.target.push_back(d.left_target_rad_s);
    r.speed.push_back(left.speed);
  }
  return r;
}

// Settling: error within `band` from `settle_s` on; oscillation: sign changes of the error once the
// speed first reached the target.
void ExpectSettles(const SpeedTrace& r, double dt, double settle_s, double band, int max_sign_changes) {
  const double final_target = r.target.back();
  const size_t from = static_cast<size_t>(settle_s / dt);
  for (size_t k = from; k < r.speed.size(); ++k) ASSERT_NEAR(r.speed[k], final_target, band) << "at " << k * dt << " s";
  size_t first = 0;
  while (first < r.speed.size() && std::abs(r.speed[first] - final_target) > band) ++first;
  int sign_changes = 0;
  for (size_t k = first + 1; k < r.speed.size(); ++k) {
    const double e0 = final_target - r.speed[k - 1], e1 = final_target - r.speed[k];
    if (std::abs(e1) > band / 2 && e0 * e1 < 0) ++sign_changes;
  }
  EXPECT_LE(sign_changes, max_sign_changes);
  double peak = 0;
  for (double s : r.speed) peak = std::max(peak, s);
  EXPECT_LT(peak, final_target * 1.05) << "overshoot";
}

TEST(WheelController, LowPassFilterReachesItsTimeConstant) {
  LowPassFilter f(0.1, 0.001);
  double y = 0;
  for (int k = 0; k < 100; ++k) y = f.Update(1.0);  // 0.1 s = one time constant
  EXPECT_NEAR(y, 1.0 - std::exp(-1.0), 0.01);
  LowPassFilter pass(0.0, 0.02);
  EXPECT_EQ(pass.Update(3.0), 3.0);
}

TEST(WheelController, StepSettlesWithin002RadPerSecondWithReportDefaults) {
  // The report's gains and filters on a motor its calibration describes.
  const WheelControllerOptions o;
  MotorCalibration model;
  const SpeedTrace r = Simulate(o, model, model.left, {{0.0, 0.0}, {0.1, 0.25}}, 4.0);
  EXPECT_NEAR(r.target.back(), 0.25 / RobotGeometry{}.wheel_radius_m, 1e-6);
  ExpectSettles(r, o.dt_s, 2.0, 0.02, /*max_sign_changes=*/1);  // no oscillation
}

TEST(WheelController, FeedbackRemovesAModelErrorThatFeedForwardAloneLeaves) {
  // The motor is 15 % weaker than its calibration says (a worn battery).
  MotorCalibration model;
  WheelCalibration weak = model.left;
  weak.forward.slope *= 1.15;
  WheelControllerOptions o;
  o.ki = 2.0;  // an integral that acts within seconds at 50 Hz
  o.kd = 0.0;
  const SpeedTrace pid = Simulate(o, model, weak, {{0.1, 0.25}}, 6.0);
  // One damped swing (the wheel-speed and PWM filters lag the P term): < 5 % overshoot, settled.
  ExpectSettles(pid, o.dt_s, 3.0, 0.02, /*max_sign_changes=*/2);
  WheelControllerOptions ff = o;
  ff.feedback = false;
  const SpeedTrace open = Simulate(ff, model, weak, {{0.1, 0.25}}, 5.0);
  EXPECT_GT(std::abs(open.speed.back() - open.target.back()), 0.5);  // what the feedback removed
}

TEST(WheelController, SaturatedCommandDoesNotWindUp) {
  // 0.9 m/s needs 21 rad/s; the motor tops out near 13.7. After 3 s of that the command drops to
  // 0.2 m/s (4.8 rad/s): with anti-windup the wheel follows at once.
  MotorCalibration model;
  WheelControllerOptions o;
  o.ki = 2.0;
  o.kd = 0.0;
  o.max_integral_rad_s = 50.0;  // the clamp alone would hide wind-up
  const std::vector<std::pair<double, double>> schedule = {{0.0, 0.9}, {3.0, 0.2}};
  // Wind-up shows as a wheel that stays fast after the drop: time until it first comes within
  // 0.5 rad/s of the new target.
  auto settle_after_drop = [&](const SpeedTrace& r) {
    const size_t drop = static_cast<size_t>(3.0 / o.dt_s);
    for (size_t k = drop; k < r.speed.size(); ++k) {
      if (std::abs(r.speed[k] - r.target.back()) < 0.5) return (k - drop) * o.dt_s;
    }
    return 1e9;
  };
  const double with = settle_after_drop(Simulate(o, model, model.left, schedule, 8.0));
  WheelControllerOptions wind = o;
  wind.anti_windup = false;
  const double without = settle_after_drop(Simulate(wind, model, model.left, schedule, 8.0));
  WheelControllerOptions open = o;  // the filters' own lag: feed-forward alone, nothing to wind up
  open.feedback = false;
  const double filters = settle_after_drop(Simulate(open, model, model.left, schedule, 8.0));
  RecordProperty("settle_with_anti_windup_s", std::to_string(with));
  RecordProperty("settle_without_anti_windup_s", std::to_string(without));
  RecordProperty("settle_feed_forward_only_s", std::to_string(filters));
  EXPECT_LT(with, filters + 0.1);
  EXPECT_GT(without, filters + 1.0);
}

}  // namespace
}  // namespace mbot::motion
