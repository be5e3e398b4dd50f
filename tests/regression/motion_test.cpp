// Motion on real logs: odometry recomputed from the encoders and the IMU of the legacy
// drive_square log against its motion capture (the reports' Figures 4-6 claim the gyro helps).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "run_config.hpp"

namespace mbot::app {
namespace {

TEST(MotionRegression, GyroFusedOdometryBeatsEncodersOnDriveSquare) {
  const std::string j = RunConfig("odometry.ini", "odometry_drive_square", {}, "odometry.json");
  ASSERT_FALSE(j.empty());
  auto xy = [&](const char* v) { return Get(j, {v, "aligned", "xy_m", "rmse"}); };
  auto th = [&](const char* v) { return Get(j, {v, "aligned", "theta_deg", "rmse"}); };
  auto final_heading = [&](const char* v) { return std::abs(Get(j, {v, "anchored", "final_error", "theta_deg"})); };
  for (const char* fused : {"gyrodometry", "imu_yaw"}) {
    RecordProperty(std::string(fused) + "_xy_rmse_m", std::to_string(xy(fused)));
    EXPECT_LT(xy(fused), xy("encoders")) << fused;
    EXPECT_LT(th(fused), th("encoders")) << fused;
    EXPECT_LT(final_heading(fused), final_heading("encoders")) << fused;
  }
  // The margins measured when this was written (encoders 0.070 m / 9.9° / 9.2° final).
  EXPECT_LT(xy("gyrodometry"), 0.060);
  EXPECT_LT(final_heading("gyrodometry"), 3.0);
}

}  // namespace
}  // namespace mbot::app

namespace mbot::app {
namespace {

// The action-model noise fitted on the legacy drive_square log (the only legacy MBot log where the
// robot drives; in the two sweep logs it stands still). Its values go to BENCHMARKS.md beside the
// reports' 0.001/0.001 and 0.0025/0.0005. Asserted: the fit converges and both k are identifiable
// (1σ well below the value). They are not asserted near the reports': on this log the motion
// capture's short-term heading disagrees with odometry by ~13° RMS per 0.2 s window (jittered
// arrival), which the fit rightly absorbs.
TEST(MotionRegression, ActionModelFitConvergesOnDriveSquare) {
  const std::string j = RunConfig("fit_action_model.ini", "fit_drive_square", {}, "action_model_fit.json");
  ASSERT_FALSE(j.empty());
  EXPECT_NE(j.find("\"converged\": true"), std::string::npos) << j;
  const double k1 = Get(j, {"k1"}), k2 = Get(j, {"k2"});
  RecordProperty("k1", std::to_string(k1));
  RecordProperty("k2", std::to_string(k2));
  RecordProperty("windows", std::to_string(Get(j, {"windows_used"})));
  EXPECT_GT(k1, 0.0);
  EXPECT_GT(k2, 0.0);
  EXPECT_LT(Get(j, {"k1_std"}), 0.5 * k1);
  EXPECT_LT(Get(j, {"k2_std"}), 0.5 * k2);
  EXPECT_GE(Get(j, {"windows_used"}), 30);
}

// On a log where the robot never moves the fit must say so rather than report numbers.
TEST(MotionRegression, ActionModelFitOnAStandingLogSaysNoWindowMoved) {
  try {
    RunConfig("fit_action_model.ini", "fit_sweep_convex",
              {"source.path=${datasets}/botlab/legacy_2017/sweep_convex_10mx10m_5cm.log"}, "action_model_fit.json");
    FAIL() << "expected the fit to fail";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no usable window"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(::testing::TempDir() + "/fit_sweep_convex/action_model.ini"));
}

// The 2023 log's PWM and measured wheel-speed channels decode and pair; the robot stood still
// while it was recorded, so the calibration must say that no encoder counted, not fit noise.
TEST(MotionRegression, CalibrationOnTheStandingF23LogSaysTheWheelsNeverTurned) {
  try {
    RunConfig("calibrate_motors.ini", "calib_f23",
              {"source.path=${datasets}/botlab/modern_small_logs/f23_lcmlog-2023-11-07.00"}, "motor_calibration.json");
    FAIL() << "a log where the wheels never turn cannot give an acceptable calibration";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("left wheel: the encoder does not count"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mbot::app
