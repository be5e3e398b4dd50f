// The stale-sensor stop every live transport applies, on its own clock: no bus, no network.
#include "mbot/msgs/sensor_watchdog.hpp"

#include <gtest/gtest.h>

namespace mbot::msgs {
namespace {

Event Command(const std::string& channel, double v) {
  return Event{0, 0, channel, EventKind::kMotorCommand, MotorCommand::Velocity(v, 0.2)};
}

double V(const Event& e) { return std::get<MotorCommand>(e.payload).velocity.v_m_s; }

TEST(SensorWatchdog, ASilentSensorStopsTheRobotUntilItIsBack) {
  SensorWatchdog w({"LIDAR", "MBOT_ODOMETRY"}, 1.0, 0.0, 10.0);
  // Both heard every 0.1 s: nothing happens, commands pass.
  for (int k = 1; k <= 20; ++k) {
    const double t = 0.1 * k;
    w.Heard("LIDAR", t);
    w.Heard("MBOT_ODOMETRY", t);
    EXPECT_EQ(w.Check(t), SensorWatchdog::Change::kNone);
    EXPECT_FALSE(w.ZeroDue(t));
  }
  EXPECT_EQ(V(w.Filter(Command("MBOT_VEL_CMD", 0.3), "MBOT_VEL_CMD")), 0.3);
  // The lidar goes quiet at 2.0 s; odometry goes on. Halted once its silence passes 1 s.
  double t = 2.0;
  int zeros = 0;
  bool halted_at_once = false;
  for (int k = 0; k < 200; ++k) {
    t = 2.0 + 0.01 * k;
    w.Heard("MBOT_ODOMETRY", t);
    const auto change = w.Check(t);
    if (change == SensorWatchdog::Change::kHalted) {
      EXPECT_GT(t - 2.0, 1.0 - 1e-9);
      EXPECT_LT(t - 2.0, 1.02);
      halted_at_once = true;
      EXPECT_EQ(w.silent(), "LIDAR");
    }
    if (w.ZeroDue(t)) ++zeros;
  }
  EXPECT_TRUE(halted_at_once);
  EXPECT_TRUE(w.halted());
  EXPECT_EQ(w.halts(), 1);
  EXPECT_NEAR(zeros, 10, 1);  // ~1 s halted at 10 Hz
  // While halted the stack's velocity commands go out as zero (counted); others pass.
  EXPECT_EQ(V(w.Filter(Command("MBOT_VEL_CMD", 0.3), "MBOT_VEL_CMD")), 0.0);
  EXPECT_EQ(V(w.Filter(Command("OTHER", 0.3), "MBOT_VEL_CMD")), 0.3);
  EXPECT_EQ(w.held(), 1);
  // The lidar is back: commands pass again; no more zeros.
  w.Heard("LIDAR", t);
  EXPECT_EQ(w.Check(t), SensorWatchdog::Change::kResumed);
  EXPECT_FALSE(w.halted());
  EXPECT_FALSE(w.ZeroDue(t + 1.0));
  EXPECT_EQ(V(w.Filter(Command("MBOT_VEL_CMD", 0.3), "MBOT_VEL_CMD")), 0.3);
}

TEST(SensorWatchdog, ANeverHeardSensorCountsFromTheStart) {
  SensorWatchdog w({"LIDAR"}, 0.5, 10.0);
  EXPECT_EQ(w.Check(10.4), SensorWatchdog::Change::kNone);
  EXPECT_EQ(w.Check(10.6), SensorWatchdog::Change::kHalted);
  EXPECT_EQ(w.Check(10.7), SensorWatchdog::Change::kNone);  // said once
  w.Heard("UNWATCHED", 10.8);
  EXPECT_TRUE(w.halted());
}

}  // namespace
}  // namespace mbot::msgs
