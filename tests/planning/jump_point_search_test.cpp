// Jump point search against A* on the same grids: same status and the same optimal length on
// every query, a path of legal 8-connected steps, and far fewer expansions where space is open.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "mbot/common/config.hpp"
#include "mbot/planning/astar.hpp"
#include "mbot/planning/planning_config.hpp"

namespace mbot::planning {
namespace {

using mapping::OccupancyGrid;
using motion::Pose2D;

AStarOptions Uniform(SearchAlgorithm search, double radius) {
  AStarOptions o;
  o.robot_radius_m = radius;
  o.ease_start_m = 0.0;
  o.penalty_weight = 0.0;
  o.prune = PruneMode::kNone;
  o.search = search;
  return o;
}

// Random obstacles at `density`, plus a few walls with gaps so some queries are unreachable and
// others wind; widths not a multiple of 64 so row scans cross word ends at every offset.
OccupancyGrid RandomGrid(int w, int h, double density, uint32_t seed) {
  std::mt19937 rng(seed);
  std::bernoulli_distribution blocked(density);
  OccupancyGrid g(w, h, 0.05, -1.0, 2.0, -100);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (blocked(rng)) g.at(x, y) = 100;
  std::uniform_int_distribution<int> col(5, w - 6), row(5, h - 6);
  for (int k = 0; k < 3; ++k) {
    const int x = col(rng), y = row(rng);
    for (int j = 0; j < h; ++j)
      if (std::abs(j - y) > 2) g.at(x, j) = 100;
  }
  return g;
}

Pose2D CellCentre(const OccupancyGrid& g, int x, int y) {
  return {g.origin_x() + (x + 0.5) * g.resolution(), g.origin_y() + (y + 0.5) * g.resolution(), 0.0};
}

// Every step of a kNone path moves to one of the 8 neighbours, into a cell clearer than `clearance`,
// and never diagonally past a blocked side cell.
void ExpectLegalSteps(const AStarPlanner& p, const std::vector<Pose2D>& path, double res, double clearance) {
  for (size_t i = 1; i < path.size(); ++i) {
    const int dx = static_cast<int>(std::lround((path[i].x - path[i - 1].x) / res));
    const int dy = static_cast<int>(std::lround((path[i].y - path[i - 1].y) / res));
    ASSERT_LE(std::abs(dx), 1);
    ASSERT_LE(std::abs(dy), 1);
    ASSERT_TRUE(dx != 0 || dy != 0);
    ASSERT_GT(p.DistanceAt(path[i].x, path[i].y), clearance);
    if (dx != 0 && dy != 0) {
      ASSERT_GT(p.DistanceAt(path[i - 1].x + dx * res, path[i - 1].y), clearance);
      ASSERT_GT(p.DistanceAt(path[i - 1].x, path[i - 1].y + dy * res), clearance);
    }
  }
}

TEST(JumpPointSearchTest, SameStatusAndOptimalLengthAsAStar) {
  int found = 0, queries = 0;
  int64_t jps_expansions = 0, astar_expansions = 0;
  for (uint32_t seed = 1; seed <= 6; ++seed) {
    const int w = 70 + 37 * static_cast<int>(seed), h = 50 + 23 * static_cast<int>(seed);
    const double density = 0.05 + 0.06 * (seed % 4);
    const double radius = seed % 2 ? 0.0 : 0.06;  // a clearance above one cell on even seeds
    const OccupancyGrid g = RandomGrid(w, h, density, seed);
    const ObstacleDistanceGrid d(g, {});
    AStarPlanner jps(Uniform(SearchAlgorithm::kJumpPoint, radius));
    AStarPlanner astar(Uniform(SearchAlgorithm::kAStar, radius));
    jps.SetMap(d);
    astar.SetMap(d);
    std::mt19937 rng(100 + seed);
    std::uniform_int_distribution<int> xs(0, w - 1), ys(0, h - 1);
    for (int q = 0; q < 150; ++q) {
      const Pose2D s = CellCentre(g, xs(rng), ys(rng)), t = CellCentre(g, xs(rng), ys(rng));
      const PlanResult a = astar.Plan(s, t);
      const PlanResult j = jps.Plan(s, t);
      ++queries;
      ASSERT_EQ(a.status, j.status) << "seed " << seed << " query " << q;
      EXPECT_FALSE(a.jump_points);
      if (a.status != PlanStatus::kFound) continue;
      ++found;
      EXPECT_TRUE(j.jump_points || j.path.size() == 2);
      ASSERT_NEAR(j.length_m, a.length_m, 1e-9) << "seed " << seed << " query " << q;
      ASSERT_NEAR(j.cost, a.cost, 1e-9);
      ExpectLegalSteps(jps, j.path, g.resolution(), radius);
      jps_expansions += j.expansions;
      astar_expansions += a.expansions;
    }
  }
  EXPECT_GT(found, queries / 3);  // the grids are not so cluttered that few queries connect
  // On cluttered grids a jump point search can expand more nodes than A* on one query (every
  // obstacle corner is a jump point); over all of them it expands fewer.
  EXPECT_LT(jps_expansions, astar_expansions);
}

TEST(JumpPointSearchTest, ExpandsFarFewerNodesInOpenSpace) {
  OccupancyGrid g(300, 200, 0.05, 0.0, 0.0, -100);
  for (int y = 20; y < 180; ++y) g.at(150, y) = 100;  // one wall to walk round
  AStarPlanner jps(Uniform(SearchAlgorithm::kAuto, 0.1));
  AStarPlanner astar(Uniform(SearchAlgorithm::kAStar, 0.1));
  const ObstacleDistanceGrid d(g, {});
  jps.SetMap(d);
  astar.SetMap(d);
  EXPECT_TRUE(jps.UsesJumpPoints());
  const PlanResult a = astar.Plan({1.0, 5.0, 0}, {14.0, 5.0, 0});
  const PlanResult j = jps.Plan({1.0, 5.0, 0}, {14.0, 5.0, 0});
  ASSERT_EQ(j.status, PlanStatus::kFound);
  EXPECT_NEAR(j.length_m, a.length_m, 1e-9);
  EXPECT_LT(j.expansions * 20, a.expansions) << j.expansions << " vs " << a.expansions;
}

TEST(JumpPointSearchTest, ChosenOnlyWhereCostsAreUniform) {
  AStarOptions o;  // the default clearance penalty: A*
  EXPECT_FALSE(AStarPlanner(o).UsesJumpPoints());
  o.penalty_weight = 0.0;
  EXPECT_TRUE(AStarPlanner(o).UsesJumpPoints());
  o.search = SearchAlgorithm::kAStar;
  EXPECT_FALSE(AStarPlanner(o).UsesJumpPoints());
  o.search = SearchAlgorithm::kJumpPoint;
  o.penalty_weight = 1.0;
  EXPECT_THROW(AStarPlanner{o}, std::invalid_argument);

  auto parse = [](const std::string& text) {
    config::Config c = config::Config::FromString(text, "test.ini");
    config::Section s = c.GetSection("astar");
    return ParseAStarOptions(s);
  };
  EXPECT_EQ(parse("[astar]\nsearch = jps\npenalty_weight = 0\n").search, SearchAlgorithm::kJumpPoint);
  try {
    parse("[astar]\nsearch = jps\n");
    FAIL() << "jps with a penalty was accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("search"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("penalty_weight"), std::string::npos) << e.what();
  }
}

TEST(JumpPointSearchTest, StatusesAndBudget) {
  OccupancyGrid g(100, 60, 0.05, 0.0, 0.0, -100);
  for (int y = 0; y < 60; ++y) g.at(50, y) = 100;  // a wall with no gap
  AStarOptions o = Uniform(SearchAlgorithm::kJumpPoint, 0.0);
  AStarPlanner p(o);
  p.SetMap(ObstacleDistanceGrid(g, {}));
  EXPECT_EQ(p.Plan({0.5, 0.5, 0}, {4.0, 0.5, 0}).status, PlanStatus::kUnreachable);
  EXPECT_EQ(p.PlanAtClearance({0.5, 0.5, 0}, {4.0, 0.5, 0}, 0.0).status, PlanStatus::kUnreachable);
  const PlanResult same = p.Plan({0.5, 0.5, 0}, {0.51, 0.52, 1.0});
  EXPECT_EQ(same.status, PlanStatus::kFound);
  EXPECT_EQ(same.path.size(), 2u);
  const PlanResult ok = p.Plan({0.5, 0.5, 0}, {2.0, 2.5, 0});
  ASSERT_EQ(ok.status, PlanStatus::kFound);
  EXPECT_EQ(ok.path.front().x, 0.5);
  EXPECT_EQ(ok.path.back().y, 2.5);
  g.at(20, 10) = 100;  // an obstacle corner makes jump points, so the budget bites
  for (int x = 10; x < 30; ++x) g.at(x, 30) = 100;
  o.node_budget = 1;
  AStarPlanner tight(o);
  tight.SetMap(ObstacleDistanceGrid(g, {}));
  EXPECT_EQ(tight.Plan({0.5, 0.5, 0}, {2.2, 2.5, 0}).status, PlanStatus::kBudgetExhausted);
}

// A planner fed the changed cells only plans as one given the whole grid, with A* and with jump
// point search (whose bit rows must not go stale).
TEST(JumpPointSearchTest, UpdateMapPlansAsSetMap) {
  OccupancyGrid g = RandomGrid(150, 110, 0.08, 9);
  for (SearchAlgorithm search : {SearchAlgorithm::kJumpPoint, SearchAlgorithm::kAStar}) {
    AStarOptions o = Uniform(search, 0.06);
    if (search == SearchAlgorithm::kAStar) o.penalty_weight = 2.0;  // penalties updated in place too
    ObstacleDistanceGrid d(g, {});
    AStarPlanner updated(o);
    updated.SetMap(d);
    std::mt19937 rng(5);
    std::uniform_int_distribution<int> xs(0, 149), ys(0, 109);
    for (int step = 0; step < 6; ++step) {
      for (int k = 0; k < 200; ++k) {  // flip cells in a patch
        const int x = 20 * step + xs(rng) % 20, y = ys(rng);
        g.at(x, y) = g.at(x, y) > 0 ? -100 : 100;
      }
      updated.UpdateMap(d, d.Update(g));
      AStarPlanner fresh(o);
      fresh.SetMap(ObstacleDistanceGrid(g, {}));
      for (int q = 0; q < 30; ++q) {
        const Pose2D s = CellCentre(g, xs(rng), ys(rng)), t = CellCentre(g, xs(rng), ys(rng));
        const PlanResult a = updated.Plan(s, t), b = fresh.Plan(s, t);
        ASSERT_EQ(a.status, b.status);
        ASSERT_EQ(a.cost, b.cost);
        ASSERT_EQ(a.path.size(), b.path.size());
      }
    }
  }
}

}  // namespace
}  // namespace mbot::planning
