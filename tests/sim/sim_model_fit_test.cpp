// sim::FitSimModel and EstimateSensorNoise on logs the simulator made with a robot whose parameters
// are known and differ from the model's: the fit finds them from the default model, and the held-out
// part of the log is followed better after the fit than before; a standing log gives back the
// gyro's and the lidar's noise it was made with.
#include "mbot/sim/sim_model_fit.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace mbot::sim {
namespace {

using msgs::Event;
using msgs::EventKind;

// The "real" robot in a room: square-ish driving (straights and turns in place, as the botlab's
// drive_square) for 24 s, commands at 20 Hz, or standing still.
std::vector<Event> Log(const SimRobotOptions& robot, bool drive, uint64_t seed) {
  World world = World::ParseArena("name room\nbox -3 -3 3 3\n", "room.arena");
  SimRobot r(world, robot, {-1.0, -1.0, 0.0}, seed);
  std::vector<Event> log, out;
  for (int k = 0; k < 480; ++k) {
    const int64_t t = k * 50'000;
    r.AdvanceTo(t, &out);
    for (Event& e : out) log.push_back(std::move(e));
    out.clear();
    const int phase = (k / 30) % 4;  // 1.5 s per phase: straight, pause, turn, pause
    double v = 0, w = 0;
    if (drive && k >= 20) v = phase == 0 ? 0.35 : 0.0, w = phase == 2 ? 1.05 : 0.0;
    const msgs::MotorCommand c = msgs::MotorCommand::Velocity(v, w);
    log.push_back(Event{t, t, "MBOT_MOTOR_COMMAND", EventKind::kMotorCommand, c});
    r.Command(v, w);
  }
  return log;
}

SimFidelityOptions Options(const SimRobotOptions& model) {
  SimFidelityOptions o;
  o.robot = model;
  o.log_wheels = model.geometry.Odometry();
  o.lidar_min_range_m = model.lidar.min_range_m;
  o.lidar_max_range_m = model.lidar.max_range_m;
  return o;
}

TEST(SimModelFit, RecoversTheMotorsAndFirmwareOfARobotItWasNotToldAbout) {
  SimRobotOptions real;
  real.left_motor_gain = 1.06;
  real.right_motor_gain = 0.90;
  real.motor_time_constant_s = 0.03;
  real.controller.v_time_constant_s = 0.25;
  real.controller.w_time_constant_s = 0.10;
  const std::vector<Event> log = Log(real, true, 3);  // with its slip and gyro noise

  SimRobotOptions model;  // the shipped one
  model.left_motor_gain = 1.0, model.right_motor_gain = 1.0;
  model.motor_time_constant_s = 0.05;
  model.controller.v_time_constant_s = 0.15, model.controller.w_time_constant_s = 0.07;
  const SimModelFitResult f = FitSimModel(log, Options(model), {});
  ASSERT_EQ(f.parameters.size(), 5u);
  EXPECT_NEAR(f.split_s, 0.5 * f.duration_s, 3.0);  // half the motion on each side
  const auto after = [&](const std::string& key) {
    for (const FittedParameter& p : f.parameters)
      if (p.key == key) return p;
    ADD_FAILURE() << key;
    return FittedParameter{};
  };
  EXPECT_NEAR(after("left_motor_gain").after, 1.06, 0.03);
  EXPECT_NEAR(after("right_motor_gain").after, 0.90, 0.03);
  EXPECT_NEAR(after("firmware_v_time_constant_s").after, 0.25, 0.05);
  EXPECT_NEAR(after("firmware_w_time_constant_s").after, 0.10, 0.03);
  EXPECT_NEAR(after("motor_time_constant_s").after, 0.03, 0.02);
  for (const FittedParameter& p : f.parameters) {
    EXPECT_TRUE(std::isfinite(p.sigma) && p.sigma > 0) << p.key;
    RecordProperty(p.key, std::to_string(p.after) + " +- " + std::to_string(p.sigma));
  }
  // The held-out part, never seen by the fit, is followed better.
  EXPECT_LT(f.held_after.wheel_speed_rmse_m_s, 0.5 * f.held_before.wheel_speed_rmse_m_s);
  EXPECT_LT(f.held_after.path_drift_m_per_m, f.held_before.path_drift_m_per_m);
  EXPECT_LT(f.fit_after.wheel_speed_rmse_m_s, f.fit_before.wheel_speed_rmse_m_s);
}

TEST(SimModelFit, AStandingLogGivesBackItsSensorsNoise) {
  SimRobotOptions real;
  real.imu.gyro_noise_rad_s = 0.003;
  real.imu.gyro_bias_initial_rad_s = 0.0;
  real.imu.gyro_bias_walk_rad_s_sqrt_s = 0.0;
  real.lidar.range_noise_m = 0.02;
  real.lidar.dropout = 0.01;
  const std::vector<Event> log = Log(real, false, 5);
  EXPECT_FALSE(WheelsTurned(log));
  const SensorNoiseEstimate n = EstimateSensorNoise(log, Options(real), 0.5);
  EXPECT_GT(n.gyro_samples, 500);
  EXPECT_NEAR(n.gyro_noise_rad_s, 0.003, 0.0005);
  EXPECT_NEAR(n.gyro_bias_rad_s, 0.0, 0.0005);
  EXPECT_GT(n.scans, 100);
  // Each direction's spread over 0.25° bins: the noise, plus what the bin's width adds on a slanted wall.
  EXPECT_NEAR(n.range_noise_m, 0.02, 0.004);
  EXPECT_NEAR(n.no_return_rate, 0.01, 0.003);
  // A log in which the robot stood still fits no motor, and says why.
  EXPECT_THROW(FitSimModel(log, Options(real), {}), std::runtime_error);
}

}  // namespace
}  // namespace mbot::sim
