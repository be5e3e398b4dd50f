#include "mbot/planning/obstacle_distance_grid.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace mbot::planning {
namespace {

using mapping::OccupancyGrid;

// Brute force: distance between cell centres to the nearest obstacle cell.
float BruteForce(const OccupancyGrid& g, int x, int y, bool unknown_is_obstacle) {
  float best = ObstacleDistanceGrid::kInfinity;
  for (int oy = 0; oy < g.height(); ++oy) {
    for (int ox = 0; ox < g.width(); ++ox) {
      const int c = g.at(ox, oy);
      if (c > 0 || (unknown_is_obstacle && c == 0)) {
        best = std::min(best, static_cast<float>(std::hypot(ox - x, oy - y) * g.resolution()));
      }
    }
  }
  return best;
}

TEST(ObstacleDistanceGridTest, SingleObstacleGivesEuclideanDistances) {
  OccupancyGrid g(9, 7, 0.05, -1.0, 2.0, -127);
  g.at(4, 3) = 127;
  ObstacleDistanceGrid d(g, {});
  EXPECT_EQ(d.at(4, 3), 0.0f);
  EXPECT_NEAR(d.at(5, 3), 0.05, 1e-6);
  EXPECT_NEAR(d.at(5, 4), 0.05 * std::sqrt(2.0), 1e-6);
  EXPECT_NEAR(d.at(0, 0), 0.05 * std::hypot(4, 3), 1e-6);  // 0.25 m, not the 4-or-8-neighbour brushfire value
  EXPECT_NEAR(d.at(8, 6), 0.25, 1e-6);
  EXPECT_EQ(d.origin_x(), -1.0);
  EXPECT_EQ(d.resolution(), 0.05);
}

// The botlab obstacle_distance_grid check: a square wall in a 25×25 grid; inside and outside, the
// distance is the distance to the nearest wall cell.
TEST(ObstacleDistanceGridTest, BotlabSquareWall) {
  OccupancyGrid g(25, 25, 0.05, 0.0, 0.0, -50);
  for (int i = 5; i <= 19; ++i) {
    g.at(i, 5) = g.at(i, 19) = g.at(5, i) = g.at(19, i) = 100;
  }
  ObstacleDistanceGrid d(g, {});
  for (int y = 0; y < 25; ++y) {
    for (int x = 0; x < 25; ++x) {
      ASSERT_NEAR(d.at(x, y), BruteForce(g, x, y, false), 1e-6) << x << "," << y;
    }
  }
  EXPECT_NEAR(d.at(12, 12), 7 * 0.05, 1e-6);  // centre: 7 cells from every wall
  EXPECT_EQ(d.at(5, 10), 0.0f);
  EXPECT_NEAR(d.at(0, 0), 0.05 * std::hypot(5, 5), 1e-6);
}

TEST(ObstacleDistanceGridTest, MatchesBruteForceOnRandomGrids) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    const int w = 5 + rng() % 40, h = 5 + rng() % 40;
    OccupancyGrid g(w, h, 0.1, 0.0, 0.0);
    for (auto& c : g.cells()) {
      const int r = rng() % 100;
      c = r < 8 ? 100 : r < 15 ? 0 : -100;
    }
    for (bool unknown : {false, true}) {
      ObstacleDistanceGrid d(g, {unknown, 0});
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) ASSERT_NEAR(d.at(x, y), BruteForce(g, x, y, unknown), 1e-5);
      }
    }
  }
}

TEST(ObstacleDistanceGridTest, NoObstacleIsInfinite) {
  OccupancyGrid g(10, 4, 0.05, 0, 0, -127);
  ObstacleDistanceGrid d(g, {});
  EXPECT_TRUE(std::isinf(d.at(3, 2)));
  // Unknown cells block when asked to.
  g.at(0, 0) = 0;
  ObstacleDistanceGrid d2(g, {true, 0});
  EXPECT_NEAR(d2.at(3, 0), 0.15, 1e-6);
}

TEST(ObstacleDistanceGridTest, OccupiedThresholdIsStrict) {
  OccupancyGrid g(3, 1, 1.0, 0, 0, -127);
  g.at(0, 0) = 10;
  EXPECT_EQ(ObstacleDistanceGrid(g, {false, 0}).at(2, 0), 2.0f);
  EXPECT_TRUE(std::isinf(ObstacleDistanceGrid(g, {false, 10}).at(2, 0)));
}

TEST(ObstacleDistanceGridTest, UnknownMarginCountsUnseenSpaceFarther) {
  // One row: a wall at x = 0, free cells, unknown from x = 8 on.
  OccupancyGrid g(12, 1, 1.0, 0, 0, -127);
  g.at(0, 0) = 100;
  for (int x = 8; x < 12; ++x) g.at(x, 0) = 0;
  const ObstacleDistanceGrid same(g, {true, 0, 0.0});
  EXPECT_EQ(same.at(6, 0), 2.0f);  // the unknown cell at x = 8
  const ObstacleDistanceGrid margin(g, {true, 0, 1.5});
  EXPECT_EQ(margin.at(6, 0), 3.5f);  // 2 + 1.5, still nearer than the wall (6)
  EXPECT_EQ(margin.at(2, 0), 2.0f);  // walls keep their distance
  EXPECT_EQ(margin.at(8, 0), 0.0f);  // an unknown cell itself is never entered
  EXPECT_EQ(margin.at(7, 0), 2.5f);  // 1 + 1.5
  const ObstacleDistanceGrid unknown_free(g, {false, 0, 1.5});
  EXPECT_EQ(unknown_free.at(6, 0), 6.0f);  // the margin only matters when unknown is an obstacle
}

// A map that grows as an explorer's does: unknown space becomes free, walls appear, a few cells flip
// back; each Update must equal a build from scratch, cell for cell, and report every changed cell.
void ExpectUpdatesMatchScratch(int w, int h, const ObstacleDistanceOptions& options, uint32_t seed) {
  std::mt19937 rng(seed);
  OccupancyGrid g(w, h, 0.05, -2.0, 1.0, 0);  // all unknown
  for (int x = 0; x < w; ++x) g.at(x, h / 2) = (x % 7 == 0) ? 100 : -100;
  ObstacleDistanceGrid incremental(options);
  const mapping::CellRect first = incremental.Update(g);
  EXPECT_EQ(first.x0, 0);
  EXPECT_EQ(first.x1, w - 1);
  EXPECT_EQ(first.y1, h - 1);
  std::uniform_int_distribution<int> xs(0, w - 1), ys(0, h - 1), size(1, 25), kind(0, 9);
  for (int step = 0; step < 12; ++step) {
    const std::vector<float> before = incremental.distances();
    // A patch seen (free with some walls), and now and then one far-away cell flipped.
    const int cx = xs(rng), cy = ys(rng), r = size(rng);
    for (int y = std::max(0, cy - r); y <= std::min(h - 1, cy + r); ++y) {
      for (int x = std::max(0, cx - r); x <= std::min(w - 1, cx + r); ++x) {
        const int k = kind(rng);
        g.at(x, y) = k == 0 ? 100 : k == 1 ? 0 : -100;
      }
    }
    if (step % 3 == 0) g.at(xs(rng), ys(rng)) = step % 2 ? 100 : -100;
    const mapping::CellRect changed = incremental.Update(g);
    const ObstacleDistanceGrid scratch(g, options);
    ASSERT_EQ(incremental.distances(), scratch.distances()) << "step " << step;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const size_t i = static_cast<size_t>(y) * w + x;
        const bool inside =
            !changed.empty() && x >= changed.x0 && x <= changed.x1 && y >= changed.y0 && y <= changed.y1;
        if (!inside) {
          ASSERT_EQ(before[i], scratch.distances()[i]) << "cell " << x << "," << y << " changed outside";
        }
      }
    }
  }
  EXPECT_TRUE(incremental.Update(g).empty());  // nothing changed
}

TEST(ObstacleDistanceGridTest, IncrementalUpdatesEqualRebuilds) {
  ExpectUpdatesMatchScratch(61, 47, {}, 1);
  ExpectUpdatesMatchScratch(83, 29, {true, 0, 0.0, -1}, 2);
  ExpectUpdatesMatchScratch(70, 90, {true, 0, 0.07, -1}, 3);   // a separate unknown margin
  ExpectUpdatesMatchScratch(420, 300, {true, 0, 0.0, -1}, 4);  // large enough for the threaded passes
}

TEST(ObstacleDistanceGridTest, UpdateOfAnotherFrameRebuildsWhole) {
  OccupancyGrid a(20, 10, 0.05, 0.0, 0.0, -100), b(20, 10, 0.05, 0.5, 0.0, -100), c(25, 10, 0.05, 0.0, 0.0, -100);
  a.at(3, 3) = b.at(3, 3) = c.at(3, 3) = 100;
  ObstacleDistanceGrid d(a, {});
  const mapping::CellRect moved = d.Update(b);
  EXPECT_EQ(moved.x1, 19);
  EXPECT_EQ(moved.y1, 9);
  EXPECT_EQ(d.origin_x(), 0.5);
  const mapping::CellRect grown = d.Update(c);
  EXPECT_EQ(grown.x1, 24);
  EXPECT_EQ(d.distances(), ObstacleDistanceGrid(c, {}).distances());
}

}  // namespace
}  // namespace mbot::planning
