#include "mbot/planning/exploration.hpp"

#include <gtest/gtest.h>

#include "exploration_sim.hpp"

namespace mbot::planning {
namespace {

using mapping::OccupancyGrid;
using motion::Pose2D;

// A 4 m × 3 m arena at 0.05 m: three rooms joined by 0.5 m doors, and a dead-end alcove.
OccupancyGrid Arena() {
  OccupancyGrid g(80, 60, 0.05, -1.0, -1.0, -100);
  auto wall = [&](int x0, int y0, int x1, int y1) {
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) g.at(x, y) = 100;
    }
  };
  wall(0, 0, 79, 0);
  wall(0, 59, 79, 59);
  wall(0, 0, 0, 59);
  wall(79, 0, 79, 59);
  wall(30, 0, 30, 40);  // room 1 | room 2, door at the top (rows 41..50)
  wall(30, 51, 30, 59);
  wall(55, 20, 79, 20);  // room 2 / room 3 below, door at columns 31..40
  wall(41, 20, 54, 20);
  wall(60, 40, 60, 58);  // an alcove in the top right
  return g;
}

TEST(ExplorationTest, ExploresEveryReachableRegionAndEndsAtHome) {
  ExplorationOptions o;
  const Pose2D home{-0.5, -0.5, 0.0};
  const testing::ScriptedRun run = testing::RunScripted(Arena(), home, o, 1.5);
  EXPECT_EQ(run.final_state, ExplorationState::kCompleted) << run.reason;
  EXPECT_GE(run.coverage, 0.99);
  EXPECT_LE(std::hypot(run.final_pose.x - home.x, run.final_pose.y - home.y), 0.03);
  EXPECT_GT(run.min_true_clearance_m, o.astar.robot_radius_m);
  EXPECT_GT(run.paths, 3);
}

// A pocket of space the sensor never sees into (unknown in the truth: rays stop at it) behind a
// 0.15 m slot in room 3's wall: its frontier stays. The robot goes there, waits, gives it up,
// explores the rest, goes home — and says the exploration is incomplete, with the frontier's count
// and place, instead of "completed".
TEST(ExplorationTest, FrontierLeftBehindEndsIncompleteWithCountAndPlace) {
  OccupancyGrid truth = Arena();
  for (int y = 1; y <= 10; ++y) {
    for (int x = 70; x <= 78; ++x) truth.at(x, y) = 0;  // never seen
  }
  for (int y = 0; y <= 11; ++y) truth.at(69, y) = 100;
  for (int x = 69; x <= 79; ++x) truth.at(x, 11) = 100;
  for (int y = 5; y <= 7; ++y) truth.at(69, y) = -100;  // the slot
  ExplorationOptions o;
  o.frontier.min_cells = 1;
  const Pose2D home{-0.5, -0.5, 0.0};
  const testing::ScriptedRun run = testing::RunScripted(truth, home, o, 1.5);
  EXPECT_EQ(run.final_state, ExplorationState::kIncomplete) << run.reason;
  EXPECT_LE(std::hypot(run.final_pose.x - home.x, run.final_pose.y - home.y), 0.03);
  EXPECT_GE(run.coverage, 0.99);  // everything else was explored first
  ASSERT_EQ(run.left.size(), 1u) << run.reason;
  EXPECT_NEAR(run.left[0].x, -1.0 + 69.5 * 0.05, 0.06);
  EXPECT_NEAR(run.left[0].y, -1.0 + 6.5 * 0.05, 0.06);
  EXPECT_TRUE(run.left[0].blacklisted);
  EXPECT_TRUE(run.left[0].unresolved);  // the robot stood at it and it stayed
  EXPECT_TRUE(run.left[0].reachable);
  EXPECT_NE(run.reason.find("incomplete: home reached"), std::string::npos) << run.reason;
  EXPECT_NE(run.reason.find("1 frontier(s) left"), std::string::npos) << run.reason;
}

TEST(ExplorationTest, HomeCutOffEndsInFailedWithTheReason) {
  ExplorationOptions o;
  const Pose2D home{-0.5, -0.5, 0.0};
  bool walled = false;
  const testing::ScriptedRun run = testing::RunScripted(
      Arena(), home, o, 1.5, 5000, [&](int, const Pose2D& pose, OccupancyGrid* truth, OccupancyGrid* known) {
        if (walled || std::hypot(pose.x - home.x, pose.y - home.y) < 1.5) return;
        walled = true;  // a closed ring of wall 0.3 m around home, seen at once
        for (int y = 0; y < truth->height(); ++y) {
          for (int x = 0; x < truth->width(); ++x) {
            double wx, wy;
            truth->CellToWorld(x, y, &wx, &wy);
            const double r = std::hypot(wx - home.x, wy - home.y);
            if (r >= 0.3 && r <= 0.36) truth->at(x, y) = known->at(x, y) = 100;
          }
        }
      });
  ASSERT_TRUE(walled);
  EXPECT_EQ(run.final_state, ExplorationState::kFailed);
  EXPECT_NE(run.reason.find("home unreachable"), std::string::npos) << run.reason;
}

TEST(ExplorationTest, WaitsInInitializingUntilTheFirstUpdateThenFixesHome) {
  Explorer e;
  EXPECT_EQ(e.state(), ExplorationState::kInitializing);
  OccupancyGrid g = Arena();
  const ExplorationUpdate u = e.Update(g, {-0.5, -0.5, 0}, 0.0);
  // A fully known map: no frontier, so it goes home at once, and it is home.
  EXPECT_EQ(e.home().x, -0.5);
  EXPECT_EQ(u.state, ExplorationState::kReturningHome);
  EXPECT_EQ(e.Update(g, {-0.5, -0.5, 0}, 1.0).state, ExplorationState::kCompleted);
}

TEST(ExplorationTest, OffTheMapFails) {
  Explorer e;
  const ExplorationUpdate u = e.Update(Arena(), {10, 10, 0}, 0.0);
  EXPECT_EQ(u.state, ExplorationState::kFailed);
  EXPECT_NE(u.reason.find("off the map"), std::string::npos);
}

}  // namespace
}  // namespace mbot::planning
