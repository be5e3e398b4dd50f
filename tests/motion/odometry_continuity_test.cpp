#include "mbot/motion/odometry_continuity.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace mbot::motion {
namespace {

// A robot driving a curve at 0.3 m/s, its odometry reported at 50 Hz; at 10 s its firmware restarts
// and the odometry starts again from zero while the robot keeps driving.
TEST(OdometryContinuity, ARestartIsReAnchoredAndNormalDrivingIsUntouched) {
  OdometryContinuity c;
  Pose2D truth, raw, restart_offset;
  Pose2D last;
  for (int k = 0; k <= 1000; ++k) {
    const int64_t t_us = k * 20000;
    if (k > 0) truth = truth.Compose(Pose2D{0.3 * 0.02, 0.0, 0.2 * 0.02});
    if (k == 500) restart_offset = truth.Inverse();  // the firmware's new frame: here is zero
    raw = restart_offset.Compose(truth);
    last = c.Update(t_us, raw);
    if (k < 500) {
      EXPECT_NEAR(last.x, truth.x, 1e-9);
      EXPECT_NEAR(last.y, truth.y, 1e-9);
    }
  }
  EXPECT_EQ(c.restarts(), 1);
  EXPECT_EQ(c.last_restart_us(), 500 * 20000);
  // After the restart the continuous pose lags the truth by the one step the jump swallowed.
  const Pose2D step{0.3 * 0.02, 0.0, 0.2 * 0.02};
  const Pose2D expected = truth.Compose(step.Inverse());
  EXPECT_NEAR(last.x, expected.x, 1e-6);
  EXPECT_NEAR(last.y, expected.y, 1e-6);
  EXPECT_NEAR(WrapAngle(last.theta - expected.theta), 0.0, 1e-6);
}

// A long gap in the messages (a silent link) is not a restart: the robot may have driven on.
TEST(OdometryContinuity, AGapAllowsWhatTheRobotCouldDriveInIt) {
  OdometryContinuity c;
  c.Update(0, {0, 0, 0});
  c.Update(3'000'000, {0.9, 0.0, 0.5});  // 3 s later, 0.9 m on: 0.3 m/s
  EXPECT_EQ(c.restarts(), 0);
  c.Update(3'020'000, {5.0, 0.0, 0.5});  // 4 m in 20 ms: no robot does that…
  c.Update(3'040'000, {5.0, 0.0, 0.5});  // …and it stays there: a restart
  EXPECT_EQ(c.restarts(), 1);
}

// One corrupt message (a float's bytes changed on the link) is dropped, not taken for a restart.
TEST(OdometryContinuity, OneCorruptMessageIsDropped) {
  OdometryContinuity c;
  EXPECT_NEAR(c.Update(0, {1.0, 2.0, 0.1}).x, 1.0, 1e-12);
  EXPECT_NEAR(c.Update(20'000, {1.0, 2.0, 0.1}).x, 1.0, 1e-12);
  EXPECT_NEAR(c.Update(40'000, {7e13, 2.0, 0.1}).x, 1.0, 1e-12);  // beyond ±1e5 m: never a pose
  EXPECT_NEAR(c.Update(60'000, {1.5, 2.0, 0.1}).x, 1.0, 1e-12);   // a jump: held until the next one
  const Pose2D p = c.Update(80'000, {1.006, 2.0, 0.1});           // back where it was: that was corrupt
  EXPECT_NEAR(p.x, 1.006, 1e-12);
  EXPECT_NEAR(p.y, 2.0, 1e-12);
  EXPECT_EQ(c.restarts(), 0);
  EXPECT_EQ(c.outliers(), 2);
}

// The fault relay's `mixed` run: a corrupt message, then its duplicate. The copy agreed with the
// jump and made it a restart, and the map grew a room outside the maze.
TEST(OdometryContinuity, ADuplicateOfACorruptMessageConfirmsNothing) {
  OdometryContinuity c;
  c.Update(0, {1.0, 2.0, 0.1});
  c.Update(20'000, {1.004, 2.0, 0.1});
  EXPECT_NEAR(c.Update(40'000, {1.604, 2.0, 0.1}).x, 1.004, 1e-12);  // corrupt: held
  EXPECT_NEAR(c.Update(40'000, {1.604, 2.0, 0.1}).x, 1.004, 1e-12);  // its duplicate: still held
  EXPECT_NEAR(c.Update(60'000, {1.012, 2.0, 0.1}).x, 1.012, 1e-12);  // back: it was corrupt
  EXPECT_EQ(c.restarts(), 0);
  EXPECT_EQ(c.duplicates(), 1);
  // A real restart is still one: the next, later message agrees with the jump.
  c.Update(80'000, {0.0, 0.0, 0.0});
  c.Update(80'000, {0.0, 0.0, 0.0});
  const Pose2D p = c.Update(100'000, {0.0, 0.0, 0.0});
  EXPECT_EQ(c.restarts(), 1);
  EXPECT_NEAR(p.x, 1.012, 1e-12);
}

// The mission places messages at their arrival: a duplicate arrives later, but carries the stamp.
TEST(OdometryContinuity, ADuplicateIsKnownByItsStampWhenTimesAreArrivals) {
  OdometryContinuity c;
  c.Update(0, {1.0, 2.0, 0.1}, 500);
  c.Update(20'000, {1.004, 2.0, 0.1}, 520);
  c.Update(41'000, {1.604, 2.0, 0.1}, 540);                               // corrupt
  EXPECT_NEAR(c.Update(43'000, {1.604, 2.0, 0.1}, 540).x, 1.004, 1e-12);  // its copy, 2 ms later
  EXPECT_NEAR(c.Update(61'000, {1.012, 2.0, 0.1}, 560).x, 1.012, 1e-12);
  EXPECT_EQ(c.restarts(), 0);
  EXPECT_EQ(c.duplicates(), 1);
}

}  // namespace
}  // namespace mbot::motion
