// The forklift model: engaging a crate through its slot, lifting, carrying, setting down, stacking
// and falling, and what stops the robot on the way.
#include "mbot/sim/forklift.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <variant>

#include "mbot/sim/sim_robot.hpp"

namespace mbot::sim {
namespace {

using motion::Pose2D;

World Arena(const std::string& crates) { return World::ParseArena("box -2 -2 2 2\n" + crates, "forklift.arena"); }

// The geometry these tests work out by hand: tips 15 cm ahead, 6 cm tines.
ForkliftOptions Enabled() {
  ForkliftOptions o;
  o.enabled = true;
  o.tip_x_m = 0.15;
  o.tine_length_m = 0.06;
  return o;
}

// Moves the robot in a straight line (1 mm steps) as far as the fork lets it, stepping the fork
// 20 ms per step; returns the contact that stopped it (kFree when it got there).
ForkContact Drive(Forklift* fork, Pose2D* pose, const Pose2D& to) {
  const double d = std::hypot(to.x - pose->x, to.y - pose->y);
  const int n = std::max(1, static_cast<int>(std::ceil(d / 0.001)));
  const Pose2D from = *pose;
  for (int i = 1; i <= n; ++i) {
    const double s = static_cast<double>(i) / n;
    const Pose2D next{from.x + s * (to.x - from.x), from.y + s * (to.y - from.y), to.theta};
    const ForkContact c = fork->Check(*pose, next);
    if (c != ForkContact::kFree) return c;
    *pose = next;
    fork->Step(0.02, *pose);
  }
  return ForkContact::kFree;
}

// Holds the robot still until the tines are at their target.
void Settle(Forklift* fork, const Pose2D& pose) {
  for (int i = 0; i < 1000 && fork->height_m() != fork->target_m(); ++i) fork->Step(0.02, pose);
}

TEST(Forklift, EngagesThroughTheSlotLiftsCarriesAndSetsDown) {
  World w = Arena("crate 7 1.0 0 0\n");
  Forklift fork(&w, Enabled());
  Pose2D pose{0.5, 0.0, 0.0};
  // The crate's near face is at x = 0.95; the tips (0.15 ahead) reach it at x = 0.80.
  ASSERT_EQ(Drive(&fork, &pose, {0.825, 0.0, 0.0}), ForkContact::kFree);
  EXPECT_EQ(fork.engaged(), 0);  // tips 2.5 cm in
  // The body (radius 0.1) would touch the crate at x = 0.85; the engaged crate is under the tines.
  EXPECT_TRUE(w.Collides(0.86, 0.0, 0.1, -1));
  EXPECT_FALSE(w.Collides(0.86, 0.0, 0.1, fork.engaged()));
  // Fully in at 6 cm: the robot stops there, without a collision.
  EXPECT_EQ(Drive(&fork, &pose, {0.9, 0.0, 0.0}), ForkContact::kFullyIn);
  EXPECT_NEAR(pose.x, 0.86, 0.002);

  EXPECT_FALSE(fork.Command(0.05));
  Settle(&fork, pose);
  EXPECT_TRUE(fork.carrying());
  const Crate& c = w.crates()[0];
  EXPECT_TRUE(c.carried);
  EXPECT_NEAR(c.z_m, 0.02, 1e-9);  // 5 cm tines, 3 cm slot
  EXPECT_TRUE(c.lifted);
  EXPECT_FALSE(c.OnFloor());
  EXPECT_NEAR(w.Raycast(0.0, 0.0, 0.0, 5.0), 1.99, 1e-6);  // the lidar sees past a lifted crate

  // Carried: it moves with the robot; lowered, it stands on the floor where it was taken.
  ASSERT_EQ(Drive(&fork, &pose, {0.36, 0.0, 0.0}), ForkContact::kFree);
  EXPECT_NEAR(w.crates()[0].pose.x, 0.5, 0.001);
  fork.Command(0.0);
  Settle(&fork, pose);
  EXPECT_FALSE(w.crates()[0].carried);
  EXPECT_TRUE(w.crates()[0].OnFloor());
  EXPECT_EQ(fork.engaged(), 0);  // the tines are still under it …
  ASSERT_EQ(Drive(&fork, &pose, {0.2, 0.0, 0.0}), ForkContact::kFree);
  EXPECT_EQ(fork.engaged(), -1);  // … until the robot backs off
  EXPECT_NEAR(w.crates()[0].pose.x, 0.5, 0.001);
  EXPECT_FALSE(w.crates()[0].fell);
}

TEST(Forklift, OffCentreOrSkewOrHighTipsHitTheCrate) {
  for (const Pose2D& approach :
       {Pose2D{0.5, 0.03, 0.0}, Pose2D{1.0 - 0.5 * std::cos(0.3), -0.5 * std::sin(0.3), 0.3}}) {
    World w = Arena("crate 7 1.0 0 0\n");
    Forklift fork(&w, Enabled());
    Pose2D pose = approach;
    const Pose2D to{pose.x + 0.4 * std::cos(pose.theta), pose.y + 0.4 * std::sin(pose.theta), pose.theta};
    EXPECT_EQ(Drive(&fork, &pose, to), ForkContact::kHit) << approach.y << " " << approach.theta;
    EXPECT_EQ(fork.engaged(), -1);
  }
  World w = Arena("crate 7 1.0 0 0\n");
  Forklift fork(&w, Enabled());
  Pose2D pose{0.5, 0.0, 0.0};
  fork.Command(0.05);  // above the slot, below the crate's top: the tips meet its side
  Settle(&fork, pose);
  EXPECT_EQ(Drive(&fork, &pose, {0.9, 0.0, 0.0}), ForkContact::kHit);
  EXPECT_NEAR(pose.x, 0.8, 0.002);
  fork.Command(0.1);  // above its top: the tines pass over (the body stops at it)
  Settle(&fork, pose);
  EXPECT_EQ(Drive(&fork, &pose, {0.85, 0.0, 0.0}), ForkContact::kFree);
}

// Picks up crate 0 at (1, 0) from the west and turns round to face south-east; returns the pose.
Pose2D PickUp(Forklift* fork, double lift_to) {
  Pose2D pose{0.5, 0.0, 0.0};
  EXPECT_EQ(Drive(fork, &pose, {0.83, 0.0, 0.0}), ForkContact::kFree);
  EXPECT_EQ(fork->engaged(), 0);
  fork->Command(lift_to);
  Settle(fork, pose);
  EXPECT_TRUE(fork->carrying());
  return pose;
}

TEST(Forklift, StacksOnTheCrateBelowWithinTheTolerance) {
  World w = Arena("crate 7 1.0 0 0\ncrate 8 1.0 -0.6 0\n");
  Forklift fork(&w, Enabled());
  Pose2D pose = PickUp(&fork, 0.12);  // underside at 9 cm, above crate 8's top (8 cm)
  // Turned to face south (the carried crate's pose follows the robot's), then over crate 8 with the
  // carried crate's centre 1 cm off crate 8's (it rides 0.17 m ahead of the robot's centre).
  pose.theta = -M_PI / 2;
  fork.Step(0.0, pose);
  const Pose2D over{1.0, -0.6 + 0.17 + 0.01, -M_PI / 2};
  ASSERT_EQ(Drive(&fork, &pose, {0.83, -0.2, -M_PI / 2}), ForkContact::kFree);
  ASSERT_EQ(Drive(&fork, &pose, over), ForkContact::kFree);
  fork.Command(0.0);
  Settle(&fork, pose);
  const Crate& top = w.crates()[0];
  EXPECT_FALSE(top.carried);
  EXPECT_EQ(top.on_id, 8);
  EXPECT_NEAR(top.z_m, 0.08, 1e-9);
  EXPECT_FALSE(top.fell);
  EXPECT_NEAR(fork.height_m(), 0.08, 1e-9);  // the tines stay in its slot, on crate 8's top
  EXPECT_TRUE(w.crates()[1].OnFloor());
}

TEST(Forklift, FallsWhenSetDownOffCentre) {
  World w = Arena("crate 7 1.0 0 0\ncrate 8 1.0 -0.6 0\n");
  Forklift fork(&w, Enabled());
  Pose2D pose = PickUp(&fork, 0.12);
  pose.theta = -M_PI / 2;
  fork.Step(0.0, pose);
  ASSERT_EQ(Drive(&fork, &pose, {0.83, -0.2, -M_PI / 2}), ForkContact::kFree);
  ASSERT_EQ(Drive(&fork, &pose, {0.95, -0.6 + 0.17, -M_PI / 2} /* 5 cm off */), ForkContact::kFree);
  fork.Command(0.0);
  Settle(&fork, pose);
  const Crate& fallen = w.crates()[0];
  EXPECT_TRUE(fallen.fell);
  EXPECT_TRUE(fallen.OnFloor());
  EXPECT_EQ(fallen.on_id, -1);
  EXPECT_FALSE(fallen.Overlaps(w.crates()[1]));
  EXPECT_EQ(fork.engaged(), -1);
}

TEST(Forklift, ACarriedCrateHitsWallsAndCratesItIsNotAbove) {
  World w = Arena("crate 7 1.0 0 0\ncrate 8 1.0 -0.6 0\n");
  Forklift fork(&w, Enabled());
  Pose2D pose = PickUp(&fork, 0.06);  // underside at 3 cm: below crate 8's top
  pose.theta = -M_PI / 2;
  fork.Step(0.0, pose);
  ASSERT_EQ(Drive(&fork, &pose, {0.83, -0.2, -M_PI / 2}), ForkContact::kFree);
  ASSERT_EQ(Drive(&fork, &pose, {1.0, -0.2, -M_PI / 2}), ForkContact::kFree);
  EXPECT_EQ(Drive(&fork, &pose, {1.0, -0.6, -M_PI / 2}), ForkContact::kHit);
  EXPECT_NEAR(w.crates()[0].pose.y, -0.6 + 0.1, 0.003);  // its south face met crate 8's north face
  // Raised above crate 8 it passes over; the south wall (inner face at y = -1.99) stops it.
  fork.Command(0.15);
  Settle(&fork, pose);
  EXPECT_EQ(Drive(&fork, &pose, {1.0, -1.9, -M_PI / 2}), ForkContact::kHit);
  EXPECT_NEAR(w.crates()[0].pose.y, -1.99 + 0.05, 0.012);
}

TEST(Forklift, CommandsOutOfRangeAreClamped) {
  World w = Arena("");
  Forklift fork(&w, Enabled());
  EXPECT_TRUE(fork.Command(0.5));
  EXPECT_DOUBLE_EQ(fork.target_m(), 0.15);
  EXPECT_TRUE(fork.Command(-1.0));
  EXPECT_DOUBLE_EQ(fork.target_m(), 0.0);
  EXPECT_TRUE(fork.Command(std::nan("")));
  EXPECT_FALSE(fork.Command(0.1));
  ForkliftOptions bad = Enabled();
  bad.max_height_m = -1;
  EXPECT_THROW(Forklift(&w, bad), std::invalid_argument);
}

// The simulated robot drives its tines into a crate, lifts it, and says so on its channels.
TEST(Forklift, SimRobotPublishesStatusAndCrates) {
  World w = Arena("crate 5 0.6 0 0\n");
  SimRobotOptions o;
  o.forklift.enabled = true;  // the default tines: tips 18 cm ahead
  SimRobot robot(w, o, {0.0, 0.0, 0.0}, 3);
  std::vector<Event> events;
  robot.Command(0.1, 0.0);
  int64_t t = 0;
  while (robot.true_pose().x < 0.41 && t < 10'000'000) {  // tips 4 cm into the face at x = 0.55
    t += 20'000;
    robot.Command(0.1, 0.0);
    robot.AdvanceTo(t, &events);
  }
  robot.Command(0.0, 0.0);
  EXPECT_EQ(robot.collisions(), 0);
  EXPECT_EQ(robot.forklift()->engaged(), 0);
  robot.CommandFork(0.1);
  robot.AdvanceTo(t + 3'000'000, &events);
  EXPECT_TRUE(w.crates()[0].carried);
  EXPECT_TRUE(robot.CommandFork(1.0));
  EXPECT_EQ(robot.forklift_commands_clamped(), 1);

  int statuses = 0, crate_messages = 0;
  const msgs::ForkliftStatus* last = nullptr;
  const msgs::CrateStates* crates = nullptr;
  for (const Event& e : events) {
    if (e.kind == EventKind::kForkliftStatus) {
      ++statuses;
      EXPECT_EQ(e.channel, "MBOT_FORKLIFT_STATUS");
      last = &std::get<msgs::ForkliftStatus>(e.payload);
    } else if (e.kind == EventKind::kCrates) {
      ++crate_messages;
      EXPECT_EQ(e.channel, "SIM_CRATES");
      crates = &std::get<msgs::CrateStates>(e.payload);
    }
  }
  const double seconds = (t + 3'000'000) * 1e-6;
  EXPECT_NEAR(statuses, 10 * seconds, 4);  // 10 Hz, and one more at each change
  EXPECT_EQ(crate_messages, 4);            // the start, engaged, carried, clear of the floor
  ASSERT_TRUE(last && crates);
  EXPECT_EQ(last->crate_id, 5);
  EXPECT_TRUE(last->carrying);
  EXPECT_NEAR(last->height_m, 0.1, 1e-9);
  ASSERT_EQ(crates->crates.size(), 1u);
  EXPECT_TRUE(crates->crates[0].carried);
}

TEST(Forklift, WithoutOneCratesAreObstaclesAndNoForkliftMessages) {
  World w = Arena("crate 5 0.6 0 0\n");
  SimRobot robot(w, SimRobotOptions{}, {0.0, 0.0, 0.0}, 3);
  EXPECT_FALSE(robot.CommandFork(0.1));
  std::vector<Event> events;
  for (int64_t t = 20'000; t <= 8'000'000; t += 20'000) {
    robot.Command(0.1, 0.0);
    robot.AdvanceTo(t, &events);
  }
  EXPECT_EQ(robot.collisions(), 1);
  EXPECT_NEAR(robot.true_pose().x, 0.45, 0.005);
  for (const Event& e : events) EXPECT_NE(e.kind, EventKind::kForkliftStatus);
}

}  // namespace
}  // namespace mbot::sim
