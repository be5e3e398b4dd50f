#include "mbot/sim/world.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "mbot/drivers/map_io.hpp"
#include "../drivers/test_util.hpp"

namespace mbot::sim {
namespace {

using namespace mbot::drivers;  // map files
using namespace mbot::msgs;     // the event and source types the simulator speaks

constexpr double kPi = 3.14159265358979323846;

std::string ParseError(const std::string& text) {
  try {
    World::ParseArena(text, "a.arena");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "(no error)";
}

// Distance from (x, y) inside the box [0, w] x [0, h] along `a` to the inner wall surfaces.
double BoxDistance(double w, double h, double half_t, double x, double y, double a) {
  const double dx = std::cos(a), dy = std::sin(a);
  double d = 1e18;
  if (dx > 0) d = std::min(d, (w - half_t - x) / dx);
  if (dx < 0) d = std::min(d, (half_t - x) / dx);
  if (dy > 0) d = std::min(d, (h - half_t - y) / dy);
  if (dy < 0) d = std::min(d, (half_t - y) / dy);
  return d;
}

// Points strictly inside [x0 + m, x1 - m] x [y0 + m, y1 - m] on a deterministic scatter.
std::vector<std::pair<double, double>> Scatter(double x0, double y0, double x1, double y1, double m, int n) {
  std::vector<std::pair<double, double>> pts;
  for (int i = 0; i < n; ++i) {
    const double u = std::fmod(0.5 + i * 0.6180339887, 1.0), v = std::fmod(0.5 + i * 0.7548776662, 1.0);
    pts.emplace_back(x0 + m + u * (x1 - x0 - 2 * m), y0 + m + v * (y1 - y0 - 2 * m));
  }
  return pts;
}

// A free room of cells [1, w-2] x [1, h-2] with an occupied border, origin (0, 0).
mapping::OccupancyGrid WalledGrid(int w, int h, double res) {
  mapping::OccupancyGrid g(w, h, res, 0.0, 0.0, 127);
  for (int j = 1; j < h - 1; ++j) {
    for (int i = 1; i < w - 1; ++i) g.at(i, j) = -127;
  }
  return g;
}

TEST(SimWorld, ParseErrorsNameTheLineAndToken) {
  EXPECT_EQ(ParseError("# walls\n\nwall 0 0 1\n"), "a.arena:3: 'wall' needs 4 numbers, got 3");
  EXPECT_EQ(ParseError("wall 0 0 1 1 1\n"), "a.arena:1: 'wall' needs 4 numbers, got 5");
  EXPECT_EQ(ParseError("wall 0 0 1 1\nwal 0 0 1 1\n"),
            "a.arena:2: unknown statement 'wal' (known: name, resolution, thickness, wall, box, pose, crate, "
            "crates_at_random, stack)");
  EXPECT_EQ(ParseError("wall 0 0 1 x1\n"), "a.arena:1: 'wall': 'x1' is not a number");
  EXPECT_EQ(ParseError("box 0 0 1 1e400\n"), "a.arena:1: 'box': '1e400' is not a finite number");
  EXPECT_EQ(ParseError("wall 0 0 1 nan\n"), "a.arena:1: 'wall': 'nan' is not a finite number");
  EXPECT_EQ(ParseError("wall 0 0 inf 1\n"), "a.arena:1: 'wall': 'inf' is not a finite number");
  EXPECT_EQ(ParseError("wall 0 0 1 1\nwall 2 2 2 2  # a post?\n"), "a.arena:2: 'wall' has zero length");
  EXPECT_EQ(ParseError("box 0 0 0 1\n"), "a.arena:1: 'box' has zero width or height");
  EXPECT_EQ(ParseError("resolution 0.001\nwall 0 0 1 1\n"),
            "a.arena:1: 'resolution' 0.001 out of range [0.005, 0.5] m");
  EXPECT_EQ(ParseError("resolution 0.05\nresolution 0.05\n"), "a.arena:2: 'resolution' given twice (first at line 1)");
  EXPECT_EQ(ParseError("thickness 0\n"), "a.arena:1: 'thickness' 0 out of range [0.001, 1] m");
  EXPECT_EQ(ParseError("thickness 0.02\nwall 0 0 1 0\nthickness 0.05\n"),
            "a.arena:3: 'thickness' 0.05 differs from the 0.02 m of the walls before (line 2); an arena has one "
            "wall thickness");
  EXPECT_EQ(ParseError("pose start 0 0\n"), "a.arena:1: 'pose' needs <label> <x> <y> <theta_deg> (4 values), got 3");
  EXPECT_EQ(ParseError("pose start 0 0 1e308\n"),
            "a.arena:1: 'pose': heading 1e308 deg is not a heading (|theta| <= 360000)");
  EXPECT_EQ(ParseError("wall 0 0 1 1\npose start 0 0 0\npose start 1 0 0\n"),
            "a.arena:3: a second 'pose start' (the first is on line 2)");
  EXPECT_EQ(ParseError("name\n"), "a.arena:1: 'name' needs a text");
  EXPECT_EQ(ParseError("name a room  # no walls yet\npose start 0 0 0\n"),
            "a.arena: no walls (an arena needs at least one 'wall' or 'box')");
  EXPECT_EQ(ParseError("wall 0 0 1e6 0\n").rfind("a.arena: the walls span", 0), 0u);
  // A repeated thickness that does not change anything is fine.
  EXPECT_NO_THROW(World::ParseArena("thickness 0.02\nwall 0 0 1 0\nthickness 0.02\nwall 0 0 0 1\n", "a.arena"));
}

TEST(SimWorld, ParsesNamePosesAndBoxes) {
  const World w = World::ParseArena(
      "name  Two rooms   # comment\r\n"
      "resolution 0.05\n"
      "thickness 0.04\n"
      "box 0 0 2 1\n"
      "wall 1 0 1 0.4\n"
      "pose start 0.5 0.5 90\n"
      "pose target 1.5 0.5 -90\n"
      "pose target 1.5 0.7 270\n",
      "rooms.arena");
  EXPECT_EQ(w.name(), "Two rooms");
  EXPECT_FALSE(w.is_grid_world());
  EXPECT_EQ(w.walls().size(), 5u);
  EXPECT_DOUBLE_EQ(w.wall_thickness(), 0.04);
  EXPECT_DOUBLE_EQ(w.truth().resolution(), 0.05);
  ASSERT_EQ(w.poses().size(), 3u);
  EXPECT_EQ(w.poses()[0].label, "start");
  EXPECT_NEAR(w.poses()[0].pose.theta, kPi / 2, 1e-12);
  const auto targets = w.PosesLabelled("target");
  ASSERT_EQ(targets.size(), 2u);
  EXPECT_DOUBLE_EQ(targets[0].y, 0.5);  // file order
  EXPECT_NEAR(targets[0].theta, -kPi / 2, 1e-12);
  EXPECT_NEAR(targets[1].theta, -kPi / 2, 1e-12);  // 270° wrapped
  EXPECT_TRUE(w.PosesLabelled("dropoff").empty());
  // Without a name statement the name is the file's stem.
  EXPECT_EQ(World::ParseArena("wall 0 0 1 0\n", "dir/hall.arena").name(), "hall");
}

TEST(SimWorld, TruthCoversTheWallsWithAMarginAndNoGaps) {
  const World w = World::ParseArena("resolution 0.05\nthickness 0.001\nbox 0 0 2 1\n", "a.arena");
  const auto& g = w.truth();
  EXPECT_LT(g.origin_x(), -0.1);
  EXPECT_GT(g.origin_x() + g.width() * g.resolution(), 2.1);
  const auto stats = g.CountCells();
  EXPECT_EQ(stats.unknown, 0);
  EXPECT_GT(stats.occupied, 0);
  // Every cell whose centre lies within thickness/2 + resolution/2 of a wall is wall.
  int cx, cy;
  g.WorldToCell(1.0, 0.0, &cx, &cy);
  EXPECT_EQ(g.at(cx, cy), 127);
  g.WorldToCell(1.0, 0.5, &cx, &cy);
  EXPECT_EQ(g.at(cx, cy), -127);
  // A thin diagonal wall (far thinner than a cell) still separates its two sides 4-connectedly.
  const World diamond = World::ParseArena(
      "resolution 0.05\nthickness 0.001\n"
      "wall 1 0 1.7 0.9\nwall 1.7 0.9 1 1.55\nwall 1 1.55 0.33 0.8\nwall 0.33 0.8 1 0\n",
      "diamond.arena");
  const auto mask = ReachableFreeMask(diamond, {1.0, 0.8, 0.0});
  int inside = 0;
  for (int j = 0; j < diamond.truth().height(); ++j) {
    for (int i = 0; i < diamond.truth().width(); ++i) {
      if (!mask[static_cast<size_t>(j) * diamond.truth().width() + i]) continue;
      ++inside;
      double x, y;
      diamond.truth().CellToWorld(i, j, &x, &y);
      EXPECT_GT(diamond.ClearanceAt(x, y), 0.0);
      ASSERT_TRUE(x > 0.3 && x < 1.75 && y > -0.05 && y < 1.6) << x << " " << y;
    }
  }
  EXPECT_GT(inside, 100);
}

TEST(SimWorld, ArenaRaycastMatchesAnalyticBox) {
  const double t = 0.02;
  const World w = World::FromSegments({{0, 0, 2, 0}, {2, 0, 2, 1.5}, {2, 1.5, 0, 1.5}, {0, 1.5, 0, 0}}, t, 0.025);
  for (const auto& [x, y] : Scatter(0, 0, 2, 1.5, 0.02, 40)) {
    for (int k = 0; k < 97; ++k) {
      const double a = -kPi + k * (2 * kPi / 97) + 0.001;
      ASSERT_NEAR(w.Raycast(x, y, a, 12.0), BoxDistance(2, 1.5, t / 2, x, y, a), 1e-9) << x << " " << y << " " << a;
    }
    EXPECT_DOUBLE_EQ(w.Raycast(x, y, 0.3, 0.01), 0.01);  // nothing nearer than max range
  }
  // Axis-aligned rays and rays into the corners.
  EXPECT_NEAR(w.Raycast(1, 0.75, 0, 12), 0.99, 1e-12);
  EXPECT_NEAR(w.Raycast(1, 0.75, kPi, 12), 0.99, 1e-12);
  EXPECT_NEAR(w.Raycast(1, 0.75, kPi / 2, 12), 0.74, 1e-12);
  EXPECT_NEAR(w.Raycast(1.24, 0.74, kPi / 4, 12), 0.75 * std::sqrt(2.0), 1e-12);  // into the corner
  // From outside: the outer surface (and nothing beyond the extent of the world).
  EXPECT_NEAR(w.Raycast(-1, 0.75, 0, 12), 0.99, 1e-12);
  EXPECT_DOUBLE_EQ(w.Raycast(-1, 0.75, kPi, 12), 12.0);
  // Rounded caps: a ray grazing past the end of a lone wall hits its round end.
  const World lone = World::FromSegments({{0, 0, 1, 0}}, 0.2, 0.025);
  EXPECT_NEAR(lone.Raycast(-1, 0, 0, 12), 0.9, 1e-12);
  EXPECT_NEAR(lone.Raycast(1.5, 0.05, kPi, 12), 0.5 - std::sqrt(0.1 * 0.1 - 0.05 * 0.05), 1e-12);
  EXPECT_DOUBLE_EQ(lone.Raycast(1.5, 0.11, kPi, 12), 12.0);
}

TEST(SimWorld, RaysFromInsideAWallAreZero) {
  const World w = World::FromSegments({{0, 0, 2, 0}, {0, 0, 0, 1}}, 0.04, 0.025);
  for (int k = 0; k < 8; ++k) {
    EXPECT_EQ(w.Raycast(1.0, 0.015, k * kPi / 4, 12), 0.0);
    EXPECT_EQ(w.Raycast(-0.02, 0.5, k * kPi / 4, 12), 0.0);  // on the surface
    EXPECT_EQ(w.Raycast(2.01, 0.0, k * kPi / 4, 12), 0.0);   // in the round cap
  }
  EXPECT_EQ(w.ClearanceAt(1.0, 0.015), 0.0);
  EXPECT_TRUE(w.Collides(1.0, 0.015, 0.0));
  const World g = World::FromGrid(WalledGrid(10, 8, 0.1));
  EXPECT_EQ(g.Raycast(0.05, 0.35, 0.0, 12), 0.0);  // wall cell
  EXPECT_EQ(g.Raycast(-1.0, 0.35, 0.0, 12), 0.0);  // outside the grid
  EXPECT_EQ(g.ClearanceAt(0.05, 0.35), 0.0);
  EXPECT_EQ(g.ClearanceAt(-1.0, 0.35), 0.0);
  EXPECT_TRUE(g.Collides(-1.0, 0.35, 0.01));
}

TEST(SimWorld, GridRaycastMatchesAnalyticBoxWithinACell) {
  const double res = 0.05;
  const World w = World::FromGrid(WalledGrid(40, 30, res));  // free [0.05, 1.95] x [0.05, 1.45]
  EXPECT_TRUE(w.is_grid_world());
  for (const auto& [x, y] : Scatter(0.05, 0.05, 1.95, 1.45, 0.01, 40)) {
    for (int k = 0; k < 97; ++k) {
      const double a = -kPi + k * (2 * kPi / 97) + 0.001;
      // Cell-exact: the free room's boundary is exactly where the box's inner surface is.
      const double expected = BoxDistance(2.0, 1.5, res, x, y, a);
      ASSERT_NEAR(w.Raycast(x, y, a, 12.0), expected, 1e-9) << x << " " << y << " " << a;
    }
  }
  EXPECT_DOUBLE_EQ(w.Raycast(1, 0.7, 0, 0.5), 0.5);
  // Against an arena world rasterised from the same box, along the walls' normals: within a cell
  // (the raster's walls are thicker, so oblique rays differ by more).
  const World arena = World::FromSegments({{0, 0, 2, 0}, {2, 0, 2, 1.5}, {2, 1.5, 0, 1.5}, {0, 1.5, 0, 0}}, 0.02, res);
  const World raster = World::FromGrid(arena.truth());
  for (const auto& [x, y] : Scatter(0, 0, 2, 1.5, 0.1, 20)) {
    for (int k = 0; k < 4; ++k) {
      EXPECT_NEAR(raster.Raycast(x, y, k * kPi / 2, 12), arena.Raycast(x, y, k * kPi / 2, 12), res);
    }
  }
}

// Clearance is the distance to the nearest surface: a disc just smaller does not collide, one just
// larger does, and no ray from the point is shorter (while the best of many is about as long).
void ExpectClearanceAgreesWithRays(const World& w, double x, double y) {
  const double c = w.ClearanceAt(x, y);
  ASSERT_GT(c, 1e-5) << x << " " << y;
  EXPECT_TRUE(w.Collides(x, y, c + 1e-6)) << x << " " << y;
  EXPECT_FALSE(w.Collides(x, y, c - 1e-6)) << x << " " << y;
  double shortest = 1e9;
  for (int k = 0; k < 3600; ++k) shortest = std::min(shortest, w.Raycast(x, y, k * kPi / 1800, 20.0));
  EXPECT_GE(shortest, c - 1e-9) << x << " " << y;
  EXPECT_LE(shortest, c + 2e-3) << x << " " << y;
}

TEST(SimWorld, ClearanceAndCollidesAgreeWithRaycast) {
  const World arena = World::ParseArena("box 0 0 2 1.5\nwall 0.8 0.6 1.3 0.9\nwall 1.6 1.5 1.6 1.1\n", "a.arena");
  for (const auto& [x, y] : Scatter(0, 0, 2, 1.5, 0.03, 12)) {
    if (arena.ClearanceAt(x, y) > 1e-3) ExpectClearanceAgreesWithRays(arena, x, y);
  }
  ExpectClearanceAgreesWithRays(arena, 1.6, 1.0);  // nearest: the round end of a wall
  EXPECT_NEAR(arena.ClearanceAt(1.6, 1.0), 0.09, 1e-12);
  EXPECT_NEAR(arena.ClearanceAt(1.0, 0.2), 0.19, 1e-12);

  auto grid = WalledGrid(40, 30, 0.05);
  for (int j = 10; j < 14; ++j) grid.at(20, j) = 127;  // a post
  grid.at(30, 20) = 0;                                 // an unknown cell: wall too
  const World g = World::FromGrid(grid);
  for (const auto& [x, y] : Scatter(0.05, 0.05, 1.95, 1.45, 0.01, 12)) {
    if (g.ClearanceAt(x, y) > 1e-3) ExpectClearanceAgreesWithRays(g, x, y);
  }
  EXPECT_NEAR(g.ClearanceAt(1.0, 0.8), std::hypot(0.0, 0.1), 1e-12);   // above the post's top
  EXPECT_NEAR(g.ClearanceAt(0.9, 0.8), std::hypot(0.1, 0.1), 1e-12);   // diagonal to its corner
  EXPECT_NEAR(g.ClearanceAt(1.5, 0.4), std::hypot(0.0, 0.35), 1e-12);  // the border
  EXPECT_NEAR(g.ClearanceAt(1.6, 1.025), 0.05, 1e-12);                 // the unknown cell
}

TEST(SimWorld, GridWorldCountsUnknownAsWall) {
  // Free interior, an unknown (0) border two cells wide, nothing occupied: the robot stays inside.
  mapping::OccupancyGrid grid(20, 16, 0.05, -0.5, -0.4, 0);
  for (int j = 2; j < 14; ++j) {
    for (int i = 2; i < 18; ++i) grid.at(i, j) = -60;
  }
  grid.at(3, 12) = 10;  // weakly occupied
  const World w = World::FromGrid(grid);
  EXPECT_DOUBLE_EQ(w.wall_thickness(), 0.0);
  EXPECT_TRUE(w.poses().empty());
  EXPECT_EQ(w.truth().at(0, 0), 127);
  EXPECT_EQ(w.truth().at(3, 12), 127);
  EXPECT_EQ(w.truth().at(5, 5), -127);
  const auto stats = w.truth().CountCells();
  EXPECT_EQ(stats.free, 12 * 16 - 1);
  EXPECT_EQ(stats.unknown, 0);
  // From (0, 0) = cell (10, 8): the free interior spans x [-0.4, 0.4], y [-0.3, 0.3].
  EXPECT_NEAR(w.Raycast(0.0, 0.0, 0.0, 12), 0.4, 1e-12);
  EXPECT_NEAR(w.Raycast(0.0, 0.0, kPi, 12), 0.4, 1e-12);
  EXPECT_NEAR(w.Raycast(0.0, 0.0, -kPi / 2, 12), 0.3, 1e-12);
  EXPECT_NEAR(w.ClearanceAt(0.0, 0.0), 0.3, 1e-12);
  EXPECT_TRUE(w.Collides(0.0, 0.0, 0.3 + 1e-9));
  EXPECT_FALSE(w.Collides(0.0, 0.0, 0.3 - 1e-9));
  const auto mask = ReachableFreeMask(w, {0.0, 0.0, 0.0});
  EXPECT_EQ(std::count(mask.begin(), mask.end(), 1), 12 * 16 - 1);
  EXPECT_THROW(ReachableFreeMask(w, {-0.48, 0.0, 0.0}), std::runtime_error);  // unknown border
  EXPECT_THROW(World::FromGrid(mapping::OccupancyGrid()), std::runtime_error);
}

TEST(SimWorld, ReachableFreeMaskDoesNotLeakThroughAClosedWall) {
  const World closed = World::ParseArena("box 0 0 2 1\nwall 1 0 1 1\n", "closed.arena");
  const auto& g = closed.truth();
  auto reached_right_room = [&](const std::vector<uint8_t>& mask) {
    for (int j = 0; j < g.height(); ++j) {
      for (int i = 0; i < g.width(); ++i) {
        double x, y;
        g.CellToWorld(i, j, &x, &y);
        if (mask[static_cast<size_t>(j) * g.width() + i] && x > 1.0) return true;
      }
    }
    return false;
  };
  const auto left = ReachableFreeMask(closed, {0.5, 0.5, 0.0});
  EXPECT_FALSE(reached_right_room(left));
  const double left_area = std::count(left.begin(), left.end(), 1) * g.resolution() * g.resolution();
  EXPECT_NEAR(left_area, 0.96, 0.1);
  const World door = World::ParseArena("box 0 0 2 1\nwall 1 0 1 0.4\nwall 1 0.7 1 1\n", "door.arena");
  EXPECT_TRUE(reached_right_room(ReachableFreeMask(door, {0.5, 0.5, 0.0})));
  EXPECT_THROW(ReachableFreeMask(closed, {1.0, 0.5, 0.0}), std::runtime_error);  // in the wall
  EXPECT_THROW(ReachableFreeMask(closed, {9.0, 0.5, 0.0}), std::runtime_error);  // off the map
}

TEST(SimWorld, LoadsArenaAndMapFilesAndNamesTheFileInErrors) {
  const auto arena_path = test::TempPath("hall.arena");
  std::ofstream(arena_path) << "box 0 0 2 1\npose start 0.5 0.5 0\nbogus\n";
  try {
    World::Load(arena_path);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), arena_path +
                                         ":3: unknown statement 'bogus' (known: name, resolution, thickness, wall, "
                                         "box, pose, crate, crates_at_random, stack)");
  }
  std::ofstream(arena_path) << "box 0 0 2 1\npose start 0.5 0.5 0\n";
  const World a = World::Load(arena_path);
  EXPECT_EQ(a.name(), "hall");
  EXPECT_EQ(a.PosesLabelled("start").size(), 1u);

  const auto map_path = test::TempPath("room.map");
  WriteBotlabMap(WalledGrid(10, 8, 0.05), map_path);
  const World m = World::Load(map_path);
  EXPECT_TRUE(m.is_grid_world());
  EXPECT_EQ(m.name(), "room");
  EXPECT_NEAR(m.Raycast(0.25, 0.2, 0, 12), 0.2, 1e-12);

  const auto missing = test::TempPath("missing.arena");
  try {
    World::Load(missing);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
  EXPECT_THROW(World::Load(test::TempPath("missing.map")), std::runtime_error);
}

// Not a test: the ray caster's speed on the largest shipped maze (run with
// --gtest_also_run_disabled_tests --gtest_filter='SimWorld.DISABLED_RaycastSpeed').
TEST(SimWorld, DISABLED_RaycastSpeed) {
  const World w = World::Load(std::string(MBOT_SOURCE_DIR) + "/datasets/arenas/maze_3.arena");
  const auto grid = World::FromGrid(w.truth());
  for (const World* world : {&w, &grid}) {
    const auto pts = Scatter(-0.3, -0.3, 3.35, 2.74, 0.0, 2000);
    std::vector<std::pair<double, double>> free_pts;
    for (const auto& p : pts) {
      if (world->ClearanceAt(p.first, p.second) > 0.1) free_pts.push_back(p);
    }
    double sum = 0;
    long rays = 0;
    const auto t0 = std::chrono::steady_clock::now();
    for (int rep = 0; rep < 5; ++rep) {
      for (const auto& [x, y] : free_pts) {
        for (int k = 0; k < 360; ++k) sum += world->Raycast(x, y, k * kPi / 180, 12.0), ++rays;
      }
    }
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    long queries = 0;
    const auto t1 = std::chrono::steady_clock::now();
    for (int rep = 0; rep < 200; ++rep) {
      for (const auto& [x, y] : free_pts) queries += world->Collides(x, y, 0.1);
    }
    const double sc = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
    std::printf("%s world: %ld rays in %.3f s = %.2f M rays/s (mean range %.3f m); Collides %.0f ns/call (%ld hits)\n",
                world->is_grid_world() ? "grid " : "arena", rays, s, rays / s / 1e6, sum / rays,
                sc / (200.0 * free_pts.size()) * 1e9, queries);
  }
}

// The shipped arenas: enclosed, every named pose clear of the walls and reachable from the start.
std::vector<std::string> ShippedArenas() {
  std::vector<std::string> paths;
  for (const auto& e : std::filesystem::directory_iterator(std::string(MBOT_SOURCE_DIR) + "/datasets/arenas")) {
    if (e.path().extension() == ".arena") paths.push_back(e.path().string());
  }
  std::sort(paths.begin(), paths.end());
  return paths;
}

TEST(SimArenas, EveryShippedArenaIsEnclosedAndItsPosesReachable) {
  const auto paths = ShippedArenas();
  for (const char* name : {"convex_circuit", "maze_1", "maze_2", "maze_3", "warehouse"}) {
    EXPECT_TRUE(
        std::count(paths.begin(), paths.end(), std::string(MBOT_SOURCE_DIR) + "/datasets/arenas/" + name + ".arena"))
        << name;
  }
  for (const auto& path : paths) {
    SCOPED_TRACE(path);
    const World w = World::Load(path);
    const auto starts = w.PosesLabelled("start");
    ASSERT_EQ(starts.size(), 1u);
    const auto start = starts[0];
    for (int k = 0; k < 360; ++k) ASSERT_LT(w.Raycast(start.x, start.y, k * kPi / 180, 20.0), 20.0) << k << "°";
    EXPECT_FALSE(w.Collides(start.x, start.y, 0.1));
    const auto mask = ReachableFreeMask(w, start);
    for (const auto& p : w.poses()) {
      EXPECT_GE(w.ClearanceAt(p.pose.x, p.pose.y), 0.15) << p.label << " " << p.pose.x << " " << p.pose.y;
      int cx, cy;
      w.truth().WorldToCell(p.pose.x, p.pose.y, &cx, &cy);
      ASSERT_TRUE(w.truth().IsInside(cx, cy));
      EXPECT_TRUE(mask[static_cast<size_t>(cy) * w.truth().width() + cx])
          << p.label << " " << p.pose.x << " " << p.pose.y;
    }
    const std::string stem = std::filesystem::path(path).stem().string();
    const double area = std::count(mask.begin(), mask.end(), 1) * std::pow(w.truth().resolution(), 2);
    if (stem.rfind("maze", 0) == 0) {
      // At least 16 cells' worth: a 0.61 m cell keeps about 0.55 x 0.55 m once its walls are rasterised.
      EXPECT_GE(area, 16 * 0.55 * 0.55);
      // Every maze cell (0.61 m grid through the start cell's centre) is reachable.
      double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
      for (const auto& s : w.walls()) {
        x0 = std::min({x0, s.x0, s.x1}), x1 = std::max({x1, s.x0, s.x1});
        y0 = std::min({y0, s.y0, s.y1}), y1 = std::max({y1, s.y0, s.y1});
      }
      int cells = 0;
      for (int j = -20; j <= 20; ++j) {
        for (int i = -20; i <= 20; ++i) {
          const double x = start.x + 0.61 * i, y = start.y + 0.61 * j;
          if (x < x0 || x > x1 || y < y0 || y > y1) continue;
          ++cells;
          int cx, cy;
          w.truth().WorldToCell(x, y, &cx, &cy);
          EXPECT_TRUE(mask[static_cast<size_t>(cy) * w.truth().width() + cx]) << "cell at " << x << ", " << y;
          EXPECT_GE(w.ClearanceAt(x, y), 0.25);
        }
      }
      EXPECT_GE(cells, 16);
    }
  }
}

TEST(SimArenas, ConvexCircuitLoopsBackToTheStart) {
  const World w = World::Load(std::string(MBOT_SOURCE_DIR) + "/datasets/arenas/convex_circuit.arena");
  const auto start = w.PosesLabelled("start").at(0);
  const auto wp = w.PosesLabelled("waypoint");
  ASSERT_GE(wp.size(), 6u);
  ASSERT_LE(wp.size(), 10u);
  EXPECT_LE(std::hypot(wp.back().x - start.x, wp.back().y - start.y), 0.05);
  double length = std::hypot(wp[0].x - start.x, wp[0].y - start.y);
  for (size_t i = 1; i < wp.size(); ++i) length += std::hypot(wp[i].x - wp[i - 1].x, wp[i].y - wp[i - 1].y);
  EXPECT_GE(length, 6.0);
  EXPECT_LE(length, 8.0);
  // The legs between waypoints keep the footprint off the walls.
  motion::Pose2D prev = start;
  for (const auto& p : wp) {
    for (int k = 0; k <= 20; ++k) {
      const double s = k / 20.0;
      EXPECT_GE(w.ClearanceAt(prev.x + s * (p.x - prev.x), prev.y + s * (p.y - prev.y)), 0.25);
    }
    prev = p;
  }
}

TEST(SimArenas, WarehouseHasTargetsAndDropoffs) {
  const World w = World::Load(std::string(MBOT_SOURCE_DIR) + "/datasets/arenas/warehouse.arena");
  EXPECT_GE(w.PosesLabelled("target").size(), 7u);
  EXPECT_GE(w.PosesLabelled("dropoff").size(), 2u);
}

// Global localization needs a floor that does not look the same turned by half a circle: from
// every free pose, the scan differs from the one at the pose turned 180° about the floor's centre.
TEST(SimArenas, WarehouseLooksDifferentTurnedAround) {
  const World w = World::Load(std::string(MBOT_SOURCE_DIR) + "/datasets/arenas/warehouse.arena");
  const double cx = (-0.35 + 3.92) / 2, cy = (-0.35 + 2.7) / 2;
  int poses = 0, distinct = 0;
  for (double x = -0.2; x < 3.8; x += 0.1) {
    for (double y = -0.2; y < 2.6; y += 0.1) {
      const double mx = 2 * cx - x, my = 2 * cy - y;
      if (w.ClearanceAt(x, y) < 0.2 || w.ClearanceAt(mx, my) < 0.2) continue;
      ++poses;
      int differ = 0;  // beams whose ranges disagree by more than 0.1 m
      for (int k = 0; k < 360; ++k) {
        const double a = k * kPi / 180;
        differ += std::abs(w.Raycast(x, y, a, 12.0) - w.Raycast(mx, my, a + kPi, 12.0)) > 0.1;
      }
      distinct += differ >= 20;
    }
  }
  ASSERT_GT(poses, 100);
  EXPECT_EQ(distinct, poses);
}

TEST(SimWorld, RenderKnownMapDrawsTheWallsAndTheReachableFloor) {
  const World w = World::Load(std::string(MBOT_SOURCE_DIR) + "/datasets/arenas/warehouse.arena");
  const mapping::OccupancyGrid m = RenderKnownMap(w, 0.05);
  EXPECT_DOUBLE_EQ(m.resolution(), 0.05);
  int cx, cy;
  m.WorldToCell(0.0, 0.0, &cx, &cy);  // the start
  EXPECT_EQ(m.at(cx, cy), -127);
  m.WorldToCell(-0.35, 1.0, &cx, &cy);  // on the left wall
  EXPECT_EQ(m.at(cx, cy), 127);
  m.WorldToCell(0.9, 0.55, &cx, &cy);  // inside a shelf block: not reachable, not a wall
  EXPECT_EQ(m.at(cx, cy), 0);
  // Every occupied cell is within a cell of a wall, every free one clear of the walls.
  for (int y = 0; y < m.height(); ++y) {
    for (int x = 0; x < m.width(); ++x) {
      double wx, wy;
      m.CellToWorld(x, y, &wx, &wy);
      if (m.at(x, y) > 0) {
        EXPECT_LE(w.ClearanceAt(wx, wy), 0.025 + 1e-9);
      }
      if (m.at(x, y) < 0) {
        EXPECT_GT(w.ClearanceAt(wx, wy), 0.025);
      }
    }
  }
}

TEST(SimWorld, RandomFreePoseIsSeededAndKeepsItsClearance) {
  const World w = World::Load(std::string(MBOT_SOURCE_DIR) + "/datasets/arenas/warehouse.arena");
  const auto a = RandomFreePose(w, 0.25, 7), b = RandomFreePose(w, 0.25, 7), c = RandomFreePose(w, 0.25, 8);
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.theta, b.theta);
  EXPECT_NE(a.x, c.x);
  const auto mask = ReachableFreeMask(w, w.PosesLabelled("start").at(0));
  for (uint64_t seed = 0; seed < 50; ++seed) {
    const auto p = RandomFreePose(w, 0.25, seed);
    EXPECT_GE(w.ClearanceAt(p.x, p.y), 0.25);
    int cx, cy;
    w.truth().WorldToCell(p.x, p.y, &cx, &cy);
    EXPECT_TRUE(mask[static_cast<size_t>(cy) * w.truth().width() + cx]) << p.x << ", " << p.y;  // not inside a shelf
  }
  EXPECT_THROW(RandomFreePose(w, 5.0, 1), std::runtime_error);
}

// Crates (Heavy Lift): exact rays and distances against a turned box, arena syntax with errors that
// name the line, and no trace in the true map the competitions score.
TEST(SimWorld, CratesAreSeenAndTouchedButNotMapped) {
  const World w =
      World::ParseArena("box -1 -1 1 1\ncrate 7 0.5 0 0\ncrate 8 -0.4 0.4 45 0.2 0.1 0.05\n", "crates.arena");
  ASSERT_EQ(w.crates().size(), 2u);
  EXPECT_EQ(w.crates()[0].id, 7);
  EXPECT_DOUBLE_EQ(w.crates()[0].width_m, 0.10);  // the defaults
  EXPECT_DOUBLE_EQ(w.crates()[1].width_m, 0.20);
  EXPECT_NEAR(w.crates()[1].pose.theta, kPi / 4, 1e-12);
  // From the origin straight at crate 7: its near face at x = 0.45.
  EXPECT_NEAR(w.Raycast(0, 0, 0, 5.0), 0.45, 1e-12);
  // Past it on either side the ray reaches the wall (inner surface at 0.99).
  EXPECT_NEAR(w.Raycast(0, 0.2, 0, 5.0), 0.99, 1e-9);
  // Through crate 8, turned 45°, from its own +x axis at 0.5 m: its face is 0.1 m from the centre.
  const double a = kPi / 4;
  const double ox = -0.4 + 0.5 * std::cos(a), oy = 0.4 + 0.5 * std::sin(a);
  EXPECT_NEAR(w.Raycast(ox, oy, a + kPi, 5.0), 0.4, 1e-9);
  EXPECT_EQ(w.Raycast(0.5, 0.0, 1.0, 5.0), 0.0);  // from inside a crate
  EXPECT_NEAR(w.ClearanceAt(0.3, 0.0), 0.15, 1e-12);
  EXPECT_TRUE(w.Collides(0.3, 0.0, 0.16));
  EXPECT_FALSE(w.Collides(0.3, 0.0, 0.14));
  EXPECT_NEAR(w.crates()[0].DistanceTo(0.6, 0.1), std::hypot(0.05, 0.05), 1e-12);  // off a corner
  // The true map holds the walls only.
  const World empty = World::ParseArena("box -1 -1 1 1\n", "empty.arena");
  EXPECT_EQ(w.truth().cells(), empty.truth().cells());
  EXPECT_NE(ParseError("box -1 -1 1 1\ncrate 7 0.5 0\n").find("a.arena:2: 'crate' needs"), std::string::npos);
  EXPECT_NE(ParseError("box -1 -1 1 1\ncrate 7.5 0.5 0 0\n").find("a.arena:2: 'crate' id 7.5"), std::string::npos);
  EXPECT_NE(ParseError("box -1 -1 1 1\ncrate 7 0.98 0 0\n").find("a.arena:2: crate 7: overlaps a wall"),
            std::string::npos)
      << ParseError("box -1 -1 1 1\ncrate 7 0.98 0 0\n");
  EXPECT_NE(ParseError("box -1 -1 1 1\ncrates_at_random 0 0 0\n").find("a.arena:2: 'crates_at_random' count 0"),
            std::string::npos);
  EXPECT_NE(ParseError("box -1 -1 1 1\ncrates_at_random 3 0 0 1 585\n").find("leave tag36h11"), std::string::npos);
  EXPECT_NE(ParseError("box -1 -1 1 1\ncrate 1 0 0 0\ncrate 2 0.05 0 0\n").find("a.arena:3: crate 2: overlaps crate 1"),
            std::string::npos);
}

// Crates and stacks that cannot be right are refused at load, naming the line.
TEST(SimWorld, CratesAndStacksThatCannotBeRightAreRefused) {
  const std::string room = "box -1 -1 1 1\n";
  EXPECT_EQ(ParseError(room + "crate 7 0.5 0 0\ncrate 7 -0.5 0 0\n"),
            "a.arena:3: 'crate' id 7 given twice (first at line 2)");
  EXPECT_EQ(ParseError(room + "crate 7 0.5 0 0\nstack 7 9\n"),
            "a.arena:3: 'stack' names crate 9, which no 'crate' or 'crates_at_random' places");
  EXPECT_EQ(ParseError(room + "crate 7 0.5 0 0\ncrate 8 -0.5 0 0\nstack 7 8\nstack 8 7\n"),
            "a.arena:5: 'stack' makes a cycle: 8 on 7 on 8");
  EXPECT_EQ(ParseError(room + "crate 7 0.5 0 0\ncrate 8 -0.5 0 0\ncrate 9 0 0.5 0\nstack 7 8\nstack 7 9\n"),
            "a.arena:6: 'stack': crate 7 is stacked twice (first at line 5)");
  EXPECT_EQ(ParseError(room + "crates_at_random 3 0 0 0.5 1\ncrate 2 0.8 0.8 0\n"),
            "a.arena:3: 'crate' id 2 is also one of the ids of 'crates_at_random' (line 2)");
  // Outside the walls: beside the room, and beside a room that has a start pose.
  EXPECT_EQ(ParseError(room + "box 3 -1 5 1\ncrate 7 2 0 0\n"), "a.arena:3: crate 7 at (2, 0) is outside the walls");
  EXPECT_EQ(ParseError(room + "box 3 -1 5 1\npose start 0 0 0\ncrate 7 4 0 0\n"),
            "a.arena:4: crate 7 at (4, 0) is outside the free space of 'pose start'");
  EXPECT_EQ(ParseError(room + "pose start 0 0 0\ncrates_at_random 2 5 5\n"),
            "a.arena:3: 'crates_at_random' centre (5, 5) is outside the free space of 'pose start'");
  // A chain (one crate on another that stands on a third) is a stack, not a cycle.
  EXPECT_NO_THROW(World::ParseArena(room + "crate 7 0.5 0 0\ncrate 8 -0.5 0 0\ncrate 9 0 0.5 0\nstack 7 8\nstack 8 9\n",
                                    "a.arena"));
}

// A nav2 map_saver map as a world: never-mapped grey 205 is wall, not floor (map_server's own rule
// with free_thresh 0.25 reads it as free); a world without a start pose starts where it has the most
// room; the floor the body reaches does not leak through a gap narrower than the robot.
TEST(SimWorld, MapSaverMapsKeepUnknownOutAndTheBodyStaysInside) {
  // 40 x 30 px at 0.05 m: a room of 254 (free) in 205 (unknown), walls of 0 with a 2-px gap on the
  // east wall onto more 254 outside.
  const int w = 40, h = 30;
  std::vector<uint8_t> px(w * h, 205);
  auto set = [&](int x, int y, uint8_t v) { px[static_cast<size_t>(h - 1 - y) * w + x] = v; };
  for (int y = 5; y <= 24; ++y) {
    for (int x = 5; x <= 24; ++x) set(x, y, (x == 5 || x == 24 || y == 5 || y == 24) ? 0 : 254);
  }
  for (int y = 5; y <= 24; ++y) {
    for (int x = 25; x <= 35; ++x) set(x, y, 254);  // floor outside the room, seen through the gap
  }
  set(24, 14, 254), set(24, 15, 254);  // the gap: 0.1 m, narrower than the robot
  const std::string dir = ::testing::TempDir() + "/saver_map";
  std::filesystem::create_directories(dir);
  {
    std::ofstream pgm(dir + "/room.pgm", std::ios::binary);
    pgm << "P5\n" << w << " " << h << "\n255\n";
    pgm.write(reinterpret_cast<const char*>(px.data()), static_cast<std::streamsize>(px.size()));
    std::ofstream(dir + "/room.yaml") << "image: room.pgm\nmode: trinary\nresolution: 0.05\norigin: [0, 0, 0]\n"
                                         "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.25\n";
  }
  EXPECT_EQ(mbot::drivers::ReadRosMap(dir + "/room.yaml").at(2, 2) < 0, true);  // map_server's reading: free
  const World world = World::Load(dir + "/room.yaml");
  const auto& g = world.truth();
  EXPECT_GE(g.at(2, 2), 0);    // 205: wall
  EXPECT_LT(g.at(10, 10), 0);  // 254: floor
  // The most room: the middle of the room (0.75 m from every wall), the same for the same seed.
  const motion::Pose2D p = MostRoomPose(world, 3);
  EXPECT_NEAR(p.x, 0.75, 0.06);
  EXPECT_NEAR(p.y, 0.75, 0.06);
  EXPECT_EQ(MostRoomPose(world, 3).theta, p.theta);
  // Free-cell flooding leaks through the 0.1 m gap; the robot's body (radius 0.1 m) does not.
  int outside_cell, y_cell;
  g.WorldToCell(1.5, 0.75, &outside_cell, &y_cell);
  const size_t outside = static_cast<size_t>(y_cell) * g.width() + outside_cell;
  EXPECT_TRUE(ReachableFreeMask(world, p)[outside]);
  const std::vector<uint8_t> body = BodyReachableMask(world, p, 0.1);
  EXPECT_FALSE(body[outside]);
  int inside_cell;
  g.WorldToCell(0.375, 0.375, &inside_cell, &y_cell);  // by a corner of the room, within the body's reach
  EXPECT_TRUE(body[static_cast<size_t>(y_cell) * g.width() + inside_cell]);
}

// Sizes that would take gigabytes or minutes are refused or stay cheap.
TEST(SimWorld, HugeArenasAreRefusedAndLongWallsLoadAlongTheirLength) {
  // 0.005 m over a 99 m box: 392 M cells (1.5 GB before), refused naming the resolution's line.
  const std::string big = ParseError("resolution 0.005\nbox 0 0 99 99\n");
  EXPECT_EQ(big.rfind("a.arena: the walls span 99 x 99 m, too large for a true map at 0.005 m", 0), 0u) << big;
  EXPECT_NE(big.find("(resolution on line 1)"), std::string::npos) << big;
  // A box of 100 m with long diagonal walls: each is rasterised along its length (this took 0.13 s a
  // wall when every cell of its bounding box was tested).
  std::string walls = "box 0 0 100 100\n";
  for (int k = 0; k < 400; ++k)
    walls += "wall 1 " + std::to_string(1 + k * 0.2) + " 99 " + std::to_string(99 - k * 0.2) + "\n";
  const World w = World::ParseArena(walls, "diagonals.arena");
  EXPECT_EQ(w.walls().size(), 404u);
  // Every cell is wall exactly when its centre is within thickness/2 + resolution/2 of a wall.
  const World few = World::ParseArena(
      "resolution 0.05\nwall 0.1 0.2 3.3 1.7\nwall 3 0.1 0.4 2.9\nwall 0 2 3 2\n"
      "wall 1 0 1 3\nwall 2 3 2.01 0\n",
      "few.arena");
  const double reach = 0.01 + 0.025;
  const auto& g = few.truth();
  int walls_seen = 0;
  for (int j = 0; j < g.height(); ++j) {
    for (int i = 0; i < g.width(); ++i) {
      double x, y;
      g.CellToWorld(i, j, &x, &y);
      double d2 = 1e18;
      for (const auto& s : few.walls()) {
        const double dx = s.x1 - s.x0, dy = s.y1 - s.y0;
        const double t = std::clamp(((x - s.x0) * dx + (y - s.y0) * dy) / (dx * dx + dy * dy), 0.0, 1.0);
        d2 = std::min(d2, std::pow(x - s.x0 - t * dx, 2) + std::pow(y - s.y0 - t * dy, 2));
      }
      const bool wall = d2 <= reach * reach;
      walls_seen += wall;
      ASSERT_EQ(g.at(i, j), wall ? 127 : -127) << i << " " << j;
    }
  }
  EXPECT_GT(walls_seen, 300);
  std::string many = "box 0 0 10 10\n";
  for (int k = 0; k < 100001; ++k) many += "wall 1 1 2 2\n";
  EXPECT_EQ(ParseError(many), "a.arena:99998: more than 100000 walls in one arena");  // 4 from the box
}

}  // namespace
}  // namespace mbot::sim
