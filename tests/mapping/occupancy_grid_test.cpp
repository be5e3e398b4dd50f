// The occupancy grid's frame conventions and CropToKnown; the exact distance transform against
// brute force.
#include "mbot/mapping/occupancy_grid.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "mbot/mapping/distance_transform.hpp"

namespace mbot::mapping {
namespace {

TEST(OccupancyGrid, CellsAndWorldAgree) {
  const OccupancyGrid g(10, 5, 0.1, -1.0, 2.0);
  int cx, cy;
  g.WorldToCell(-1.0, 2.0, &cx, &cy);
  EXPECT_EQ(cx, 0);
  EXPECT_EQ(cy, 0);
  g.WorldToCell(-0.05, 2.45, &cx, &cy);
  EXPECT_EQ(cx, 9);
  EXPECT_EQ(cy, 4);
  double x, y;
  g.CellToWorld(9, 4, &x, &y);  // the cell's centre
  EXPECT_NEAR(x, -0.05, 1e-12);
  EXPECT_NEAR(y, 2.45, 1e-12);
  g.WorldToCell(-1.01, 2.0, &cx, &cy);
  EXPECT_EQ(cx, -1);  // floor, outside
  EXPECT_FALSE(g.IsInside(cx, cy));
}

TEST(OccupancyGrid, CropToKnownKeepsTheKnownCellsAndAMarginInTheSameFrame) {
  OccupancyGrid g(100, 100, 0.05, 0.0, 0.0);
  g.at(40, 50) = 100;
  g.at(45, 52) = -100;
  const OccupancyGrid c = CropToKnown(g, 0.1);  // 2 cells of margin
  EXPECT_EQ(c.width(), 6 + 4);
  EXPECT_EQ(c.height(), 3 + 4);
  EXPECT_NEAR(c.origin_x(), 38 * 0.05, 1e-12);
  EXPECT_NEAR(c.origin_y(), 48 * 0.05, 1e-12);
  double x, y;
  g.CellToWorld(40, 50, &x, &y);
  int cx, cy;
  c.WorldToCell(x, y, &cx, &cy);
  EXPECT_EQ(c.at(cx, cy), 100);
  EXPECT_EQ(CropToKnown(OccupancyGrid(5, 5, 0.1, 0, 0), 0.1).width(), 5);  // nothing known: unchanged
}

TEST(DistanceTransform, MatchesBruteForceOnRandomMasks) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 5; ++trial) {
    const int w = 13 + trial * 7, h = 9 + trial * 5;
    std::vector<uint8_t> mask(w * h, 0);
    for (auto& m : mask) m = rng() % 23 == 0;
    const std::vector<float> d = SquaredDistanceTransform(mask, w, h);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        float best = std::numeric_limits<float>::infinity();
        for (int v = 0; v < h; ++v) {
          for (int u = 0; u < w; ++u) {
            if (mask[v * w + u]) best = std::min(best, float((u - x) * (u - x) + (v - y) * (v - y)));
          }
        }
        ASSERT_EQ(d[y * w + x], best) << "cell " << x << "," << y << " trial " << trial;
      }
    }
  }
  const std::vector<float> none = SquaredDistanceTransform(std::vector<uint8_t>(12, 0), 4, 3);
  for (float v : none) EXPECT_TRUE(std::isinf(v));
}

}  // namespace
}  // namespace mbot::mapping
