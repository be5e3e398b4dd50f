#include "mbot/planning/frontiers.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace mbot::planning {
namespace {

using mapping::OccupancyGrid;

TEST(FrontiersTest, BorderBetweenFreeAndUnknownGroupedIntoRegions) {
  // Left half known free, right half unknown, except a known-free island far right.
  OccupancyGrid g(40, 20, 0.05, 0, 0, 0);
  for (int y = 0; y < 20; ++y) {
    for (int x = 0; x < 20; ++x) g.at(x, y) = -100;
  }
  g.at(35, 10) = -100;  // a one-cell island: a frontier region of size 1
  const std::vector<Frontier> all = FindFrontiers(g, {1, 1.0});
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all[0].size(), 20);  // the column x = 19
  EXPECT_NEAR(all[0].centroid_x, 19.5 * 0.05, 1e-12);
  EXPECT_NEAR(all[0].centroid_y, 10 * 0.05, 1e-12);
  EXPECT_EQ(all[1].size(), 1);
  EXPECT_EQ(FindFrontiers(g, {5, 1.0}).size(), 1u);  // min_cells drops the island
}

// A corridor seen only by a few grazing rays: faint free cells (log-odds -3) fading into unknown.
// Counted as free, its frontier would lie deep in the faint band, out of reach; counted as unknown
// (above free_threshold), the frontier is at its mouth, where the well-seen room ends.
TEST(FrontiersTest, FaintCellsCountAsUnknownAtTheThresholds) {
  OccupancyGrid g(40, 20, 0.05, 0, 0, 0);
  for (int y = 0; y < 20; ++y) {
    for (int x = 0; x < 20; ++x) g.at(x, y) = -60;  // the room
    for (int x = 20; x < 30; ++x) g.at(x, y) = -3;  // the faint band
  }
  const std::vector<Frontier> f = FindFrontiers(g, {1, 1.0});
  ASSERT_EQ(f.size(), 1u);
  EXPECT_NEAR(f[0].centroid_x, 19.5 * 0.05, 1e-9);  // the room's last column
  FrontierOptions faint_is_free{1, 1.0, -1, 1};     // the old rule: any negative log-odds is free
  const std::vector<Frontier> old = FindFrontiers(g, faint_is_free);
  ASSERT_EQ(old.size(), 1u);
  EXPECT_NEAR(old[0].centroid_x, 29.5 * 0.05, 1e-9);  // the end of the faint band
  // A weakly hit cell (log-odds 3) is not an obstacle either at occupied_threshold 5.
  g.at(10, 10) = 3;
  EXPECT_EQ(FindFrontiers(g, {1, 1.0, -20, 5}).size(), 2u);
  EXPECT_EQ(FindFrontiers(g, {1, 1.0}).size(), 1u);
}

TEST(FrontiersTest, OccupiedCellsAreNeverFrontiers) {
  OccupancyGrid g(10, 10, 0.05, 0, 0, 0);
  for (int y = 0; y < 10; ++y) g.at(3, y) = 100;
  EXPECT_TRUE(FindFrontiers(g, {1, 1.0}).empty());
}

// A room's wall with a nook and a doorway behind which lies unknown space: the nook's unknown is
// 2 x 3 cells between walls; the doorway opens onto the whole unknown half. With min_space_m 0.25 (a
// 0.2 m robot and a cell) the nook is a pocket, the doorway not (too long), nor a small frontier in
// the open (too far from any wall).
TEST(FrontiersTest, APocketSmallerThanTheRobotIsToldFromADoorway) {
  OccupancyGrid g(40, 40, 0.05, 0, 0, 0);
  for (int y = 0; y < 40; ++y) {
    for (int x = 0; x < 20; ++x) g.at(x, y) = -100;  // the room; x >= 21 is unknown
    g.at(20, y) = 100;                               // its wall
  }
  for (int y = 20; y < 28; ++y) g.at(20, y) = -100;  // the doorway, cells 20-27
  for (int y = 4; y < 9; ++y)                        // the nook: walls round unknown cells (18-19, 5-7)
    for (int x = 17; x < 21; ++x) g.at(x, y) = (x == 17 || x == 20 || y == 4 || y == 8) ? 100 : 0;
  for (int y = 5; y < 8; ++y) g.at(17, y) = -100;  // open to the room on its left
  FrontierOptions o{1, 1.0};
  o.min_space_m = 0.25;
  const std::vector<Frontier> f = FindFrontiers(g, o);  // both are frontiers still
  ASSERT_EQ(f.size(), 2u);
  EXPECT_NEAR(f[0].centroid_y, 24 * 0.05, 1e-9);  // the doorway's: the larger first
  EXPECT_FALSE(IsPocket(f[0], g, o));
  EXPECT_TRUE(IsPocket(f[1], g, o));
  o.min_space_m = 0.0;
  EXPECT_FALSE(IsPocket(f[1], g, o));

  // A one-cell unknown hole in the middle of the room: a frontier of four cells, far from every wall.
  o.min_space_m = 0.25;
  g.at(8, 30) = 0;
  const std::vector<Frontier> h = FindFrontiers(g, o);
  ASSERT_EQ(h.size(), 3u);
  EXPECT_EQ(h[1].size(), 4);  // the doorway's 8, the hole's 4, the nook's 3
  EXPECT_NEAR(h[1].centroid_y, 30.5 * 0.05, 1e-9);
  EXPECT_FALSE(IsPocket(h[1], g, o)) << "the hole is open space";
  EXPECT_TRUE(IsPocket(h[2], g, o));
}

// A free 2 m x 1.9 m room whose right side opens to unknown space.
OccupancyGrid RoomOpenToTheRight() {
  OccupancyGrid g(60, 40, 0.05, 0, 0, 0);
  for (int y = 1; y < 39; ++y) {
    for (int x = 1; x < 40; ++x) g.at(x, y) = -100;
  }
  for (int x = 0; x < 41; ++x) g.at(x, 0) = g.at(x, 39) = 100;
  for (int y = 0; y < 40; ++y) g.at(0, y) = 100;
  return g;
}

TEST(FrontiersTest, GoalIsCentroidOrNearestReachableCell) {
  // A free room whose right side opens to unknown space; a wall segment sits on the frontier's centroid.
  const OccupancyGrid g = RoomOpenToTheRight();
  const std::vector<Frontier> f = FindFrontiers(g, {5, 1.0});
  ASSERT_EQ(f.size(), 1u);
  AStarPlanner planner;
  planner.SetMap(ObstacleDistanceGrid(g, {true, 0}));
  std::vector<int> unreachable;
  const std::vector<FrontierGoal> goals = RankFrontierGoals(f, {0.5, 1.0, 0}, g, planner, 0.10, {5, 1.0}, &unreachable);
  ASSERT_EQ(goals.size(), 1u);
  EXPECT_TRUE(unreachable.empty());
  // The centroid lies on the frontier (0.05 m from unknown space): not reachable with 0.10 m
  // clearance, so the nearest reachable cell is taken, just inside the room.
  EXPECT_LT(goals[0].target.x, f[0].centroid_x);
  EXPECT_NEAR(goals[0].target.x, f[0].centroid_x - 0.10, 0.03);
  EXPECT_NEAR(goals[0].target.y, f[0].centroid_y, 0.03);
  EXPECT_GT(goals[0].cost, 0.0);
  // A search radius too small to get off the frontier: unreachable.
  EXPECT_TRUE(RankFrontierGoals(f, {0.5, 1.0, 0}, g, planner, 0.10, {5, 0.05}, &unreachable).empty());
  EXPECT_EQ(unreachable, std::vector<int>{0});
}

TEST(FrontiersTest, GoalSeesTheFrontierRatherThanStandingBehindAWall) {
  // A corridor 0.55 m wide narrows to 0.25 m (too narrow for 0.15 m clearance) at y = 0.9 m, and its
  // narrow part opens to unknown space at y = 1.5 m. A thick wall (x 0.3-0.65 m) separates it from a
  // second corridor known up to y = 1.6 m. The reachable cell nearest the frontier's centroid is in
  // the second corridor, behind the wall (0.65 m away); the goal must be the one below the narrow
  // part (0.70 m away), which looks up it.
  OccupancyGrid g(40, 40, 0.05, 0, 0, 0);
  for (int y = 1; y < 30; ++y) {
    for (int x = 1; x < 39; ++x) g.at(x, y) = -100;
  }
  for (int y = 0; y < 40; ++y) g.at(0, y) = g.at(39, y) = 100;
  for (int x = 0; x < 40; ++x) g.at(x, 0) = 100;
  for (int y = 18; y < 40; ++y) {
    for (int x = 6; x <= 12; ++x) g.at(x, y) = 100;  // the thick wall above y = 0.9 m
  }
  for (int y = 10; y < 18; ++y) g.at(12, y) = 100;                 // the two corridors are apart from y = 0.5 m
  for (int x = 13; x < 39; ++x) g.at(x, 30) = g.at(x, 31) = -100;  // the second corridor is known higher up
  for (int x = 13; x < 39; ++x) g.at(x, 32) = 100;
  const std::vector<Frontier> f = FindFrontiers(g, {5, 1.0});
  ASSERT_EQ(f.size(), 1u);
  ASSERT_LT(f[0].centroid_x, 0.3);
  AStarPlanner planner;
  planner.SetMap(ObstacleDistanceGrid(g, {true, 0}));
  const std::vector<FrontierGoal> goals = RankFrontierGoals(f, {1.5, 0.3, 0}, g, planner, 0.15, {5, 1.0});
  ASSERT_EQ(goals.size(), 1u);
  EXPECT_LT(goals[0].target.x, 0.3) << "goal at " << goals[0].target.x << ", " << goals[0].target.y;
  EXPECT_LT(goals[0].target.y, 0.9);
}

// A viewpoint from which a frontier was seen not to resolve is not chosen again for that frontier:
// its goal moves at least the avoid radius away (the second viewpoint the explorer tries); another
// frontier's goal is not affected.
TEST(FrontiersTest, AFailedViewpointIsAvoidedForItsFrontierOnly) {
  const OccupancyGrid g = RoomOpenToTheRight();
  const std::vector<Frontier> f = FindFrontiers(g, {5, 1.0});
  ASSERT_EQ(f.size(), 1u);
  AStarPlanner planner;
  planner.SetMap(ObstacleDistanceGrid(g, {true, 0}));
  const std::vector<FrontierGoal> first = RankFrontierGoals(f, {0.5, 1.0, 0}, g, planner, 0.10, {5, 1.0});
  ASSERT_EQ(first.size(), 1u);
  AvoidViews avoid;
  avoid.radius_m = 0.25;
  avoid.views.push_back({f[0].centroid_x, f[0].centroid_y, first[0].target.x, first[0].target.y});
  const std::vector<FrontierGoal> second =
      RankFrontierGoals(f, {0.5, 1.0, 0}, g, planner, 0.10, {5, 1.0}, nullptr, avoid);
  ASSERT_EQ(second.size(), 1u);
  EXPECT_GE(std::hypot(second[0].target.x - first[0].target.x, second[0].target.y - first[0].target.y), 0.25);
  // A failed view recorded for a frontier elsewhere (its centroid beyond match_m) changes nothing.
  AvoidViews elsewhere = avoid;
  elsewhere.views[0].frontier_x -= 1.0;
  const std::vector<FrontierGoal> same =
      RankFrontierGoals(f, {0.5, 1.0, 0}, g, planner, 0.10, {5, 1.0}, nullptr, elsewhere);
  ASSERT_EQ(same.size(), 1u);
  EXPECT_DOUBLE_EQ(same[0].target.x, first[0].target.x);
  EXPECT_DOUBLE_EQ(same[0].target.y, first[0].target.y);
}

}  // namespace
}  // namespace mbot::planning
