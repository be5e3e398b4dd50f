#include "mbot/sim/maze_generator.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

#include "mbot/sim/world.hpp"

namespace mbot::sim {
namespace {

// Cells reachable from the start cell through open passages.
int ConnectedCells(const Maze& m) {
  std::vector<uint8_t> seen(static_cast<size_t>(m.cols) * m.rows, 0);
  std::vector<int> queue = {0};
  seen[0] = 1;
  for (size_t q = 0; q < queue.size(); ++q) {
    const int x = queue[q] % m.cols, y = queue[q] / m.cols;
    auto visit = [&](int nx, int ny, bool open) {
      if (!open || seen[static_cast<size_t>(ny) * m.cols + nx]) return;
      seen[static_cast<size_t>(ny) * m.cols + nx] = 1;
      queue.push_back(ny * m.cols + nx);
    };
    if (x + 1 < m.cols) visit(x + 1, y, !m.VWall(x + 1, y));
    if (x > 0) visit(x - 1, y, !m.VWall(x, y));
    if (y + 1 < m.rows) visit(x, y + 1, !m.HWall(x, y + 1));
    if (y > 0) visit(x, y - 1, !m.HWall(x, y));
  }
  return static_cast<int>(queue.size());
}

TEST(MazeGeneratorTest, OneSeedOneMazeWithinTheStyle) {
  const MazeStyle style;
  for (uint64_t seed = 1; seed <= 50; ++seed) {
    const Maze m = GenerateMaze(style, seed);
    EXPECT_EQ(m.ToArena(), GenerateMaze(style, seed).ToArena());
    EXPECT_GE(m.cols, 4);
    EXPECT_LE(m.cols, 8);
    EXPECT_GE(m.rows, 4);
    EXPECT_LE(m.rows, 8);
    EXPECT_EQ(ConnectedCells(m), m.cols * m.rows) << "seed " << seed;                   // every cell can be reached
    for (int i = 0; i < m.cols; ++i) EXPECT_TRUE(m.HWall(i, 0) && m.HWall(i, m.rows));  // closed outside
    for (int j = 0; j < m.rows; ++j) EXPECT_TRUE(m.VWall(0, j) && m.VWall(m.cols, j));
  }
  EXPECT_NE(GenerateMaze(style, 1).ToArena(), GenerateMaze(style, 2).ToArena());
}

TEST(MazeGeneratorTest, PerfectMazeHasNoLoopsAndOpeningsAddThem) {
  MazeStyle perfect;
  perfect.min_openings = perfect.max_openings = 0;
  perfect.min_rooms = perfect.max_rooms = 0;
  perfect.min_cols = perfect.max_cols = perfect.min_rows = perfect.max_rows = 6;
  const Maze m = GenerateMaze(perfect, 3);
  EXPECT_EQ(m.Loops(), 0);
  EXPECT_GT(m.DeadEnds(), 0);
  MazeStyle open = perfect;
  open.min_openings = open.max_openings = 0.3;
  const Maze o = GenerateMaze(open, 3);
  EXPECT_GT(o.openings, 0);
  EXPECT_EQ(o.Loops(), o.openings);
  // Straight carving makes longer corridors than twisty carving (summed over twenty seeds).
  MazeStyle straight = perfect, twisty = perfect;
  straight.min_straightness = straight.max_straightness = 0.95;
  twisty.min_straightness = twisty.max_straightness = 0.0;
  int straight_cells = 0, twisty_cells = 0;
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    straight_cells += GenerateMaze(straight, seed).LongestCorridor();
    twisty_cells += GenerateMaze(twisty, seed).LongestCorridor();
  }
  EXPECT_GT(straight_cells, twisty_cells + 10) << straight_cells << " vs " << twisty_cells;
}

TEST(MazeGeneratorTest, ArenaLoadsInTheSimulatorWithTheStartFree) {
  const Maze m = GenerateMaze(MazeStyle{}, 7);
  const World w = World::ParseArena(m.ToArena(), "maze_7.arena");
  const auto start = w.PosesLabelled("start");
  ASSERT_EQ(start.size(), 1u);
  EXPECT_EQ(start[0].x, 0.0);
  EXPECT_EQ(start[0].y, 0.0);
  EXPECT_NEAR(w.ClearanceAt(0, 0), 0.305 - 0.01, 1e-6);  // the middle of the start cell
  // Every cell centre is free, and every wall panel is there: the centre of cell (0, 0)'s south
  // wall is inside a wall.
  for (int y = 0; y < m.rows; ++y) {
    for (int x = 0; x < m.cols; ++x) EXPECT_GT(w.ClearanceAt(x * 0.61, y * 0.61), 0.2);
  }
  EXPECT_EQ(w.ClearanceAt(0, -0.305), 0.0);
}

TEST(MazeGeneratorTest, BadStyleIsRejectedNamingTheField) {
  MazeStyle s;
  s.min_cols = 9;  // above max_cols
  EXPECT_THROW(GenerateMaze(s, 1), std::invalid_argument);
  try {
    GenerateMaze(s, 1);
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cols"), std::string::npos) << e.what();
  }
  MazeStyle t;
  t.max_openings = 1.5;
  EXPECT_THROW(GenerateMaze(t, 1), std::invalid_argument);
}

}  // namespace
}  // namespace mbot::sim
