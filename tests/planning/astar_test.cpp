#include "mbot/planning/astar.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "mbot/common/config.hpp"
#include "mbot/planning/planning_config.hpp"

namespace mbot::planning {
namespace {

using mapping::OccupancyGrid;
using motion::Pose2D;

// A walled room of w × h cells at 0.05 m, free inside.
OccupancyGrid Room(int w, int h) {
  OccupancyGrid g(w, h, 0.05, 0.0, 0.0, -100);
  for (int x = 0; x < w; ++x) g.at(x, 0) = g.at(x, h - 1) = 100;
  for (int y = 0; y < h; ++y) g.at(0, y) = g.at(w - 1, y) = 100;
  return g;
}

// A vertical wall at column `x` with openings [lo, hi] (inclusive cell rows).
void WallWithGaps(OccupancyGrid* g, int x, const std::vector<std::pair<int, int>>& gaps) {
  for (int y = 0; y < g->height(); ++y) {
    bool open = false;
    for (auto [lo, hi] : gaps) open = open || (y >= lo && y <= hi);
    if (!open) g->at(x, y) = 100;
  }
}

AStarPlanner PlannerFor(const OccupancyGrid& g, AStarOptions o = {}) {
  AStarPlanner p(o);
  p.SetMap(ObstacleDistanceGrid(g, {}));
  return p;
}

bool PassesThroughRows(const std::vector<Pose2D>& path, double wall_x, double y_lo, double y_hi) {
  for (size_t i = 0; i + 1 < path.size(); ++i) {
    const Pose2D& a = path[i];
    const Pose2D& b = path[i + 1];
    if ((a.x - wall_x) * (b.x - wall_x) <= 0 && a.x != b.x) {
      const double y = a.y + (b.y - a.y) * (wall_x - a.x) / (b.x - a.x);
      if (y >= y_lo && y <= y_hi) return true;
    }
  }
  return false;
}

// Two openings in a wall: a short way through a gap only 0.2 m from its sides at the centre
// (narrower than radius + 0.10 m), a longer way through a 1 m gap. The easing takes the wide one.
TEST(AStarTest, EasingPrefersTheWidestCorridor) {
  OccupancyGrid g = Room(80, 60);
  WallWithGaps(&g, 40, {{4, 10}, {30, 49}});
  AStarPlanner p = PlannerFor(g);
  const PlanResult r = p.Plan({0.5, 0.3, 0}, {3.5, 0.3, 0});
  ASSERT_EQ(r.status, PlanStatus::kFound);
  EXPECT_NEAR(r.clearance_m, 0.20, 1e-9);
  EXPECT_TRUE(PassesThroughRows(r.path, 40 * 0.05 + 0.025, 30 * 0.05, 50 * 0.05));
  EXPECT_EQ(r.searches, 1);
}

TEST(AStarTest, EasingRelaxesOnlyWhenNeeded) {
  OccupancyGrid g = Room(80, 60);
  WallWithGaps(&g, 40, {{4, 10}});  // centre cell 0.20 m from both sides: needs clearance < 0.20
  AStarPlanner p = PlannerFor(g);
  const PlanResult r = p.Plan({0.5, 0.3, 0}, {3.5, 0.3, 0});
  ASSERT_EQ(r.status, PlanStatus::kFound);
  EXPECT_NEAR(r.clearance_m, 0.19, 1e-9);  // one step looser than the first rung, no more
  EXPECT_TRUE(PassesThroughRows(r.path, 40 * 0.05 + 0.025, 4 * 0.05, 11 * 0.05));
  EXPECT_EQ(r.searches, 1);  // rungs that cannot connect are skipped without a search

  // A gap of 3 cells: its centre is 0.10 m from the sides, not more than the radius.
  OccupancyGrid closed = Room(80, 60);
  WallWithGaps(&closed, 40, {{10, 12}});
  AStarPlanner q = PlannerFor(closed);
  const PlanResult u = q.Plan({0.5, 0.3, 0}, {3.5, 0.3, 0});
  EXPECT_EQ(u.status, PlanStatus::kUnreachable);
  EXPECT_EQ(u.expansions, 0);  // answered from the connectivity labels, no search
}

TEST(AStarTest, EasingLadder) {
  AStarPlanner p;
  const std::vector<double> c = p.EasingClearances();
  ASSERT_EQ(c.size(), 6u);
  EXPECT_NEAR(c.front(), 0.20, 1e-12);
  EXPECT_NEAR(c[4], 0.16, 1e-12);
  EXPECT_NEAR(c.back(), 0.10, 1e-12);
  AStarOptions once;
  once.ease_start_m = 0.0;
  EXPECT_EQ(AStarPlanner(once).EasingClearances(), std::vector<double>{0.10});
}

TEST(AStarTest, PenaltyPushesPathsOffWalls) {
  OccupancyGrid g = Room(60, 40);
  AStarOptions plain;
  plain.penalty_weight = 0.0;
  plain.prune = PruneMode::kNone;
  plain.ease_start_m = 0.0;
  AStarOptions penalised = plain;
  penalised.penalty_weight = 5.0;
  penalised.penalty_range_m = 0.8;
  auto mean_clearance = [&](const AStarOptions& o) {
    AStarPlanner p = PlannerFor(g, o);
    const PlanResult r = p.Plan({0.325, 0.325, 0}, {2.675, 0.325, 0});  // cell centres, 0.30 m off the wall
    EXPECT_EQ(r.status, PlanStatus::kFound);
    double sum = 0;
    for (const Pose2D& q : r.path) sum += p.DistanceAt(q.x, q.y);
    return sum / r.path.size();
  };
  const double without = mean_clearance(plain), with = mean_clearance(penalised);
  EXPECT_NEAR(without, 0.30, 0.03);  // straight along the wall
  EXPECT_GT(with, without + 0.15);
}

OccupancyGrid RandomBlobs(std::mt19937& rng, int w, int h, int blobs) {
  OccupancyGrid g = Room(w, h);
  for (int b = 0; b < blobs; ++b) {
    const int cx = rng() % w, cy = rng() % h, r = 1 + rng() % 4;
    for (int y = cy - r; y <= cy + r; ++y) {
      for (int x = cx - r; x <= cx + r; ++x) {
        if (g.IsInside(x, y) && std::hypot(x - cx, y - cy) <= r) g.at(x, y) = 100;
      }
    }
  }
  return g;
}

// Paths keep more than the robot radius from obstacles everywhere along their segments, whatever
// the pruning, and A* costs equal Dijkstra's optimal costs.
TEST(AStarTest, PathsStayClearAlongSegmentsAndAreOptimal) {
  std::mt19937 rng(3);
  int found = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const OccupancyGrid g = RandomBlobs(rng, 60, 50, 25);
    for (PruneMode mode : {PruneMode::kNone, PruneMode::kCollinear, PruneMode::kLineOfSight}) {
      AStarOptions o;
      o.prune = mode;
      AStarPlanner p = PlannerFor(g, o);
      const Pose2D start{0.1 + (rng() % 58) * 0.05, 0.1 + (rng() % 48) * 0.05, 0};
      const Pose2D goal{0.1 + (rng() % 58) * 0.05, 0.1 + (rng() % 48) * 0.05, 0.5};
      const PlanResult r = p.Plan(start, goal);
      if (r.status != PlanStatus::kFound) continue;
      ++found;
      EXPECT_EQ(r.path.front().x, start.x);
      EXPECT_EQ(r.path.back().x, goal.x);
      EXPECT_EQ(r.path.back().theta, goal.theta);
      for (size_t i = 0; i + 1 < r.path.size(); ++i) {
        const Pose2D& a = r.path[i];
        const Pose2D& b = r.path[i + 1];
        const int n = std::max(1, static_cast<int>(std::hypot(b.x - a.x, b.y - a.y) / 0.002));
        for (int k = 0; k <= n; ++k) {
          const double s = double(k) / n;
          ASSERT_GT(p.DistanceAt(a.x + s * (b.x - a.x), a.y + s * (b.y - a.y)), o.robot_radius_m)
              << "trial " << trial << " segment " << i;
        }
      }
      const std::vector<double> costs = p.CostsFrom(start, r.clearance_m);
      int gx, gy;
      g.WorldToCell(goal.x, goal.y, &gx, &gy);
      EXPECT_NEAR(r.cost, costs[gy * g.width() + gx], 1e-9);
    }
  }
  EXPECT_GT(found, 20);
}

TEST(AStarTest, NoDiagonalPastAnObstacleCorner) {
  OccupancyGrid g(4, 4, 1.0, 0, 0, -100);
  g.at(1, 0) = 100;
  g.at(0, 1) = 100;
  AStarOptions o;
  o.robot_radius_m = 0.0;
  o.ease_start_m = 0.0;
  AStarPlanner p = PlannerFor(g, o);
  EXPECT_EQ(p.Plan({0.5, 0.5, 0}, {1.5, 1.5, 0}).status, PlanStatus::kUnreachable);
  g.at(0, 1) = -100;  // one side open: still a corner cut, the way round is 2 straight steps
  p.SetMap(ObstacleDistanceGrid(g, {}));
  const PlanResult r = p.Plan({0.5, 0.5, 0}, {1.5, 1.5, 0});
  ASSERT_EQ(r.status, PlanStatus::kFound);
  EXPECT_NEAR(r.length_m, 2.0, 1e-12);
}

TEST(AStarTest, StatusesNotMagicValues) {
  OccupancyGrid g = Room(40, 40);
  g.at(20, 20) = 100;
  AStarPlanner p = PlannerFor(g);
  EXPECT_EQ(p.Plan({-1, 1, 0}, {1, 1, 0}).status, PlanStatus::kStartOffMap);
  EXPECT_EQ(p.Plan({1, 1, 0}, {1, 5, 0}).status, PlanStatus::kGoalOffMap);
  EXPECT_EQ(p.Plan({1.025, 1.025, 0}, {0.5, 0.5, 0}).status, PlanStatus::kStartInCollision);
  EXPECT_EQ(p.Plan({0.5, 0.5, 0}, {1.075, 1.025, 0}).status, PlanStatus::kGoalInCollision);
  const PlanResult same = p.Plan({0.5, 0.5, 0}, {0.51, 0.52, 1.0});
  EXPECT_EQ(same.status, PlanStatus::kFound);
  EXPECT_EQ(same.path.size(), 2u);
  AStarOptions tight;
  tight.node_budget = 5;
  AStarPlanner b = PlannerFor(g, tight);
  EXPECT_EQ(b.Plan({0.5, 0.5, 0}, {1.6, 1.6, 0}).status, PlanStatus::kBudgetExhausted);
  EXPECT_STREQ(ToString(PlanStatus::kBudgetExhausted), "node budget exhausted");
  AStarPlanner none;
  EXPECT_THROW(none.Plan({0, 0, 0}, {1, 1, 0}), std::logic_error);
}

TEST(AStarTest, PruneCollinearKeepsTurnsOnly) {
  std::vector<Pose2D> path;
  for (int i = 0; i <= 5; ++i) path.push_back({i * 0.05, 0, 0});
  for (int i = 1; i <= 5; ++i) path.push_back({0.25 + i * 0.05, i * 0.05, 0});
  const std::vector<Pose2D> out = PruneCollinear(path);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_NEAR(out[1].x, 0.25, 1e-12);
  EXPECT_NEAR(out[2].x, 0.5, 1e-12);
}

TEST(AStarTest, SegmentIsClearSeesThinWalls) {
  OccupancyGrid g = Room(40, 40);
  for (int y = 0; y < 40; ++y) g.at(20, y) = 100;
  AStarPlanner p = PlannerFor(g);
  EXPECT_FALSE(p.SegmentIsClear(0.5, 0.5, 1.5, 1.6, 0.0));
  EXPECT_TRUE(p.SegmentIsClear(0.5, 0.5, 0.8, 1.6, 0.1));
}

TEST(AStarTest, OptionsParsedStrictly) {
  auto cfg = config::Config::FromString("[a]\nrobot_radius_m = 0.12\nprune = line_of_sight\nnode_budget = 100\n");
  config::Section s = cfg.GetSection("a");
  const AStarOptions o = ParseAStarOptions(s);
  s.Finish();
  EXPECT_EQ(o.robot_radius_m, 0.12);
  EXPECT_EQ(o.prune, PruneMode::kLineOfSight);
  EXPECT_EQ(o.node_budget, 100);
  auto bad = config::Config::FromString("[a]\nprune = sometimes\n");
  config::Section b = bad.GetSection("a");
  EXPECT_THROW(ParseAStarOptions(b), config::ConfigError);
}

TEST(AStarPlannerTest, PlanSteppingOutLeavesTheRadiusFirst) {
  // An open room; the robot stands 0.07 m from the left wall, inside the 0.12 m planning radius.
  mapping::OccupancyGrid g(60, 40, 0.05, 0, 0, -100);
  for (int y = 0; y < 40; ++y) g.at(0, y) = g.at(59, y) = 100;
  for (int x = 0; x < 60; ++x) g.at(x, 0) = g.at(x, 39) = 100;
  AStarOptions o;
  o.robot_radius_m = 0.12;
  AStarPlanner planner(o);
  planner.SetMap(ObstacleDistanceGrid(g, {}));
  const motion::Pose2D start{0.12, 1.0, 0}, goal{2.0, 1.0, 0};
  EXPECT_EQ(planner.Plan(start, goal).status, PlanStatus::kStartInCollision);
  const PlanResult r = planner.PlanSteppingOut(start, goal);
  ASSERT_EQ(r.status, PlanStatus::kFound);
  ASSERT_GE(r.path.size(), 3u);
  EXPECT_DOUBLE_EQ(r.path.front().x, start.x);
  EXPECT_GT(planner.DistanceAt(r.path[1].x, r.path[1].y), 0.12);             // out of the radius
  EXPECT_LT(std::hypot(r.path[1].x - start.x, r.path[1].y - start.y), 0.1);  // by a short step
  EXPECT_NEAR(r.path.back().x, goal.x, 1e-9);
  // A clear start plans as Plan does.
  EXPECT_EQ(planner.PlanSteppingOut({1.0, 1.0, 0}, goal).path.size(), planner.Plan({1.0, 1.0, 0}, goal).path.size());
}

}  // namespace
}  // namespace mbot::planning
