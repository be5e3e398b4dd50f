// sim::SimFidelity on logs made by the simulator itself: a log of the same robot model and seed is
// followed exactly (no drift, no wheel-speed or yaw-rate error, every beam where the ray cast puts
// it), and a log of a robot whose right motor is weaker than the model's shows as drift.
#include "mbot/sim/sim_fidelity.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace mbot::sim {
namespace {

using motion::Pose2D;
using msgs::Event;
using msgs::EventKind;

World Room() { return World::ParseArena("name room\nbox -3 -3 3 3\n", "room.arena"); }

// The "real" robot: a SimRobot in the room driving an S-curve for 12 s, its events as a log's (the
// commands at 20 Hz; the truth, encoders, IMU and lidar as the robot publishes them).
std::vector<Event> Log(const SimRobotOptions& robot, uint64_t seed) {
  World world = Room();
  SimRobot r(world, robot, {-1.5, -1.0, 0.3}, seed);
  std::vector<Event> log, out;
  for (int k = 0; k < 240; ++k) {
    const int64_t t = k * 50'000;
    r.AdvanceTo(t, &out);
    for (Event& e : out) log.push_back(std::move(e));
    out.clear();
    const double w = k < 40 ? 0.0 : std::sin(k * 0.05) * 0.8;
    const msgs::MotorCommand c = msgs::MotorCommand::Velocity(k < 20 ? 0.0 : 0.2, w);
    log.push_back(Event{t, t, "MBOT_MOTOR_COMMAND", EventKind::kMotorCommand, c});
    r.Command(c.velocity.v_m_s, c.velocity.w_rad_s);
  }
  return log;
}

SimFidelityResult Measure(const SimRobotOptions& model, const std::vector<Event>& log, uint64_t seed) {
  SimFidelityOptions o;
  o.robot = model;
  o.log_wheels = model.geometry.Odometry();
  o.lidar_min_range_m = model.lidar.min_range_m;
  o.lidar_max_range_m = model.lidar.max_range_m;
  SimFidelity f(o, Room(), seed);
  for (const Event& e : log) f.Add(e);
  return f.Finish();
}

TEST(SimFidelity, TheModelFollowsItsOwnLogAndAWeakerWheelShowsAsDrift) {
  SimRobotOptions model;
  model.lidar.range_noise_m = 0;
  model.lidar.dropout = 0;
  const std::vector<Event> same = Log(model, 7);
  const SimFidelityResult r = Measure(model, same, 7);
  EXPECT_GT(r.true_path_m, 1.5);
  EXPECT_GT(r.commands, 200);
  EXPECT_GT(r.encoder_samples, 40);
  EXPECT_GT(r.gyro_samples, 40);
  // The same robot, the same seed, the same commands at the same times: the same path.
  EXPECT_LT(r.path_drift_m_per_m, 0.01);
  EXPECT_LT(r.path_rmse_m, 0.01);
  EXPECT_LT(r.wheel_speed_rmse_m_s, 0.01);
  EXPECT_LT(r.yaw_rate_rmse_rad_s, 0.02);  // the log's gyro has its noise and bias
  // The lidar: ranges from the true poses, ray cast in the same room, noiseless.
  EXPECT_GT(r.beams_compared, 10'000);
  EXPECT_LT(r.scan_range_residual_median_m, 0.005);
  EXPECT_NEAR(r.no_return_rate_real, r.no_return_rate_sim, 0.01);
  // The log's odometry (the firmware's) is compared too.
  EXPECT_TRUE(std::isfinite(r.odometry_drift_m_per_m));

  SimRobotOptions weak = model;
  weak.right_motor_gain = 0.85;  // the real robot's right wheel is slower than the model says
  const SimFidelityResult d = Measure(model, Log(weak, 7), 7);
  // The firmware's wheel-speed loop makes up most of the weaker motor, not all: the path bends.
  EXPECT_GT(d.path_drift_m_per_m, 10 * std::max(r.path_drift_m_per_m, 0.005));
}

TEST(SimFidelity, ALogWithoutMotionCaptureOrCommandsIsNamed) {
  SimFidelity f(SimFidelityOptions{}, std::nullopt, 1);
  f.Add(Event{0, 0, "MBOT_MOTOR_COMMAND", EventKind::kMotorCommand, msgs::MotorCommand::Velocity(0.1, 0)});
  EXPECT_THROW(
      {
        try {
          f.Finish();
        } catch (const std::runtime_error& e) {
          EXPECT_NE(std::string(e.what()).find("TRUE_POSE"), std::string::npos) << e.what();
          throw;
        }
      },
      std::runtime_error);
}

}  // namespace
}  // namespace mbot::sim
