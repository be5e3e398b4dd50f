// The Maze Explorer on generated mazes the explorer was never tuned on (libs/sim GenerateMaze with
// the default style of config/generate_mazes.ini: 4 x 4 to 8 x 8 cells, long corridors, loops, open
// rooms, dead ends). Every maze: completed, >= 99 % of the reachable free space mapped, home within
// 0.05 m, no collision.
//   MazeSample (label simulation, the default run): three mazes that once failed — a long corridor
//     seen only at a slant from its mouth (7), a frontier banded along such a corridor (9), a free
//     wall end seen faintly and touched (6).
//   MazeSweep (label mazes: ctest -C mazes -L mazes): mazes MBOT_MAZE_FIRST .. MBOT_MAZE_LAST
//     (default 1 .. 100), with a table of the results (on stdout, and in build/tests/out/maze_sweep.md
//     or MBOT_MAZE_SWEEP_MD) — the table in BENCHMARKS.md.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "../regression/run_config.hpp"
#include "mbot/sim/maze_generator.hpp"

namespace mbot::app {
namespace {

struct MazeRun {
  uint64_t seed = 0;
  sim::Maze maze;
  std::string json;  // score.json
  double wall_s = 0;
};

MazeRun ExploreGeneratedMaze(uint64_t seed) {
  MazeRun r;
  r.seed = seed;
  r.maze = sim::GenerateMaze(sim::MazeStyle{}, seed);
  const std::string dir = ::testing::TempDir() + "/generated_mazes";
  std::filesystem::create_directories(dir);
  const std::string arena = dir + "/maze_" + std::to_string(seed) + ".arena";
  std::ofstream(arena) << r.maze.ToArena();
  const auto t0 = std::chrono::steady_clock::now();
  r.json =
      RunConfig("maze_explorer.ini", "generated_maze_" + std::to_string(seed), {"source.path=" + arena}, "score.json");
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

class MazeSample : public ::testing::TestWithParam<int> {};

TEST_P(MazeSample, ExploredMappedAndHomeWithoutCollision) {
  const MazeRun r = ExploreGeneratedMaze(GetParam());
  ExpectExploredMappedAndHome(r.json);
}
INSTANTIATE_TEST_SUITE_P(GeneratedMazes, MazeSample, ::testing::Values(6, 7, 9));

double Median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

int EnvInt(const char* name, int fallback) {
  const char* v = std::getenv(name);
  return v && *v ? std::atoi(v) : fallback;
}

TEST(MazeSweep, EveryGeneratedMazeExploredMappedAndHome) {
  const int first = EnvInt("MBOT_MAZE_FIRST", 1), last = EnvInt("MBOT_MAZE_LAST", 100);
  ASSERT_LE(first, last);
  std::vector<double> coverage, time_s, error_m, rtf, cells;
  int completed = 0, collisions = 0, runs_with_collision = 0, within = 0;
  std::string outside;
  std::ostringstream rows;
  rows << "| maze | cells | loops | dead ends | longest corridor | state | coverage % | walls % | time s | home error "
          "m | "
          "collisions |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (int seed = first; seed <= last; ++seed) {
    SCOPED_TRACE("generated maze " + std::to_string(seed));
    const MazeRun r = ExploreGeneratedMaze(seed);
    ExpectExploredMappedAndHome(r.json);
    if (r.json.empty()) continue;
    const double cov = Get(r.json, {"map", "coverage"}), t = Get(r.json, {"time_s"});
    const double err = std::hypot(Get(r.json, {"final_error", "x_m"}), Get(r.json, {"final_error", "y_m"}));
    const int col = static_cast<int>(Get(r.json, {"collisions"}));
    const bool done = r.json.find("\"completed\": true") != std::string::npos;
    coverage.push_back(cov), time_s.push_back(t), error_m.push_back(err),
        rtf.push_back(Get(r.json, {"sim_seconds"}) / r.wall_s);
    cells.push_back(r.maze.cols * r.maze.rows);
    completed += done, collisions += col, runs_with_collision += col > 0;
    const double walls = Get(r.json, {"map", "wall_precision"});
    if (done && col == 0 && cov >= 0.99 && walls >= 0.95 && err <= 0.05) {
      ++within;
    } else {
      outside += (outside.empty() ? "" : ", ") + std::to_string(seed);
    }
    char row[256];
    std::snprintf(row, sizeof row, "| %d | %dx%d | %d | %d | %d | %s | %.1f | %.1f | %.1f | %.3f | %d |\n", seed,
                  r.maze.cols, r.maze.rows, r.maze.Loops(), r.maze.DeadEnds(), r.maze.LongestCorridor(),
                  done ? "completed" : "NOT completed", 100 * cov, 100 * walls, t, err, col);
    rows << row;
  }
  const int n = static_cast<int>(coverage.size());
  ASSERT_GT(n, 0);
  char summary[2048];
  std::snprintf(
      summary, sizeof summary,
      "| mazes | within every bound | completed | coverage min / median %% | time median [min, max] s | "
      "runs with a collision | home error median / max m | real-time factor median |\n"
      "|---|---|---|---|---|---|---|---|\n"
      "| %d (seeds %d-%d) | %d (outside: %s) | %d | %.1f / %.1f | %.0f [%.0f, %.0f] | %d | %.3f / %.3f | %.0f |\n",
      n, first, last, within, outside.empty() ? "none" : outside.c_str(), completed,
      100 * *std::min_element(coverage.begin(), coverage.end()), 100 * Median(coverage), Median(time_s),
      *std::min_element(time_s.begin(), time_s.end()), *std::max_element(time_s.begin(), time_s.end()),
      runs_with_collision, Median(error_m), *std::max_element(error_m.begin(), error_m.end()), Median(rtf));
  const std::string table = std::string(summary) + "\n" + rows.str();
  std::cout << table;
  const char* md = std::getenv("MBOT_MAZE_SWEEP_MD");
  const std::string md_path = md && *md ? md : ::testing::TempDir() + "/maze_sweep.md";
  std::filesystem::create_directories(std::filesystem::path(md_path).parent_path());
  std::ofstream(md_path) << table;
  EXPECT_EQ(completed, n);
  EXPECT_EQ(collisions, 0);
}

}  // namespace
}  // namespace mbot::app
