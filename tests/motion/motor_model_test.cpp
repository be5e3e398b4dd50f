// The motor model's duty/speed lines and their Ceres calibration on generated samples: known
// slope and punch with noise and outliers, a reversed polarity, a dead encoder.
#include "mbot/motion/motor_model.hpp"

#include <gtest/gtest.h>

#include <random>

namespace mbot::motion {
namespace {

// A calibration sweep of one wheel: duties from -0.9 to 0.9, speed from the true lines plus noise;
// every tenth sample is an outlier (a slip: the wheel spins 40 % faster than the line says).
std::vector<MotorSample> Sweep(const WheelCalibration& truth, uint32_t seed, double noise_rad_s = 0.05) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, noise_rad_s);
  std::vector<MotorSample> out;
  int k = 0;
  for (double d = -0.9; d <= 0.9 + 1e-9; d += 0.01) {
    for (int rep = 0; rep < 3; ++rep) {
      double w = truth.SpeedFor(d);
      if (w != 0) w += n(rng);
      if (++k % 10 == 0) w *= 1.4;
      out.push_back({d, truth.encoder_polarity * w});
    }
  }
  return out;
}

WheelCalibration Wheel(double fs, double fp, double bs, double bp) {
  WheelCalibration w;
  w.forward = {fs, fp};
  w.backward = {bs, bp};
  return w;
}

TEST(MotorModel, DutyAndSpeedAreInverseOutsideTheDeadBand) {
  WheelCalibration w = Wheel(0.065, 0.071, 0.067, -0.070);
  w.motor_polarity = -1;
  for (double speed : {-8.0, -1.0, 0.5, 3.0, 12.0}) EXPECT_NEAR(w.SpeedFor(w.DutyFor(speed)), speed, 1e-12);
  EXPECT_EQ(w.DutyFor(0.0), 0.0);
  EXPECT_EQ(w.SpeedFor(-0.05), 0.0);  // inside the punch
  EXPECT_LT(w.DutyFor(2.0), 0.0);     // reversed motor: forward needs a negative duty
  EXPECT_EQ(w.DutyFor(100.0), -1.0);  // clamped
}

TEST(MotorModel, CeresFitRecoversSlopeAndPunchWithin2PercentDespiteOutliers) {
  const WheelCalibration left = Wheel(0.071, 0.065, 0.066, -0.070), right = Wheel(0.065, 0.071, 0.067, -0.070);
  const MotorFitReport r = FitMotorCalibration(Sweep(left, 1), Sweep(right, 2), MotorFitOptions{});
  EXPECT_TRUE(r.acceptable) << (r.problems.empty() ? "" : r.problems[0]);
  auto near = [](double fit, double truth) { EXPECT_NEAR(fit, truth, 0.02 * std::abs(truth)); };
  near(r.calibration.left.forward.slope, 0.071);
  near(r.calibration.left.forward.punch, 0.065);
  near(r.calibration.left.backward.slope, 0.066);
  near(r.calibration.left.backward.punch, -0.070);
  near(r.calibration.right.forward.slope, 0.065);
  near(r.calibration.right.forward.punch, 0.071);
  near(r.calibration.right.backward.slope, 0.067);
  near(r.calibration.right.backward.punch, -0.070);
  EXPECT_GT(r.left.forward.samples, 100);
  EXPECT_GT(r.left.forward.residual_rms, 0.0);
}

TEST(MotorModel, ReversedPolarityIsDetectedAndNamed) {
  WheelCalibration wired_backwards = Wheel(0.065, 0.071, 0.067, -0.070);
  wired_backwards.encoder_polarity = -1;  // the data counts down going forward; the options say +1
  const MotorFitReport r =
      FitMotorCalibration(Sweep(Wheel(0.07, 0.07, 0.07, -0.07), 3), Sweep(wired_backwards, 4), MotorFitOptions{});
  EXPECT_FALSE(r.acceptable);
  EXPECT_TRUE(r.left.polarity_ok);
  EXPECT_FALSE(r.right.polarity_ok);
  ASSERT_EQ(r.problems.size(), 1u);
  EXPECT_NE(r.problems[0].find("right wheel: polarity reversed"), std::string::npos) << r.problems[0];
  // Told the truth, the same data calibrates.
  MotorFitOptions o;
  o.right_encoder_polarity = -1;
  EXPECT_TRUE(FitMotorCalibration(Sweep(Wheel(0.07, 0.07, 0.07, -0.07), 3), Sweep(wired_backwards, 4), o).acceptable);
}

TEST(MotorModel, DeadEncoderAndOutOfLimitLinesAreReported) {
  std::vector<MotorSample> dead;
  for (double d = -0.9; d <= 0.9; d += 0.05) dead.push_back({d, 0.0});
  const MotorFitReport r = FitMotorCalibration(Sweep(Wheel(0.15, 0.07, 0.07, -0.07), 5), dead, MotorFitOptions{});
  EXPECT_FALSE(r.acceptable);
  ASSERT_EQ(r.problems.size(), 2u);
  EXPECT_NE(r.problems[0].find("left wheel: forward slope"), std::string::npos) << r.problems[0];
  EXPECT_NE(r.problems[1].find("right wheel: the encoder does not count"), std::string::npos) << r.problems[1];
}

}  // namespace
}  // namespace mbot::motion
