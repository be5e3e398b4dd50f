// The Maze Explorer on generated mazes the explorer was never tuned on (libs/sim GenerateMaze with
// the default style of config/generate_mazes.ini: 4 x 4 to 8 x 8 cells, long corridors, loops, open
// rooms, dead ends). Every maze: completed, >= 99 % of the reachable free space mapped, home within
// 0.05 m, no collision.
//   MazeSample (label simulation, the default run): three mazes that once failed — a long corridor
//     seen only at a slant from its mouth (7), a frontier banded along such a corridor (9), a free
//     wall end seen faintly and touched (6); a pocket behind a free wall end that one viewpoint
//     does not show (24, its second viewpoint does); a map rotated 2-3 degrees in the first turn,
//     walls 48 % (64, until the sensor model measured to cells of six net hits).
//   MazeReplay (label simulation): the explorer's SLAM replayed on its own recording.
//   MazeAtTheMeasuredNoise (label simulation): maze 27, which the refine's moments mapped 1 % small
//     at the lidar's measured range noise until hits weighed their range.
//   The sweep over mazes 1-100 (label mazes) is config/sweep_mazes.ini, run by
//     tests/sweep/maze_sweep.sh under GNU parallel and merged into one table.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

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

MazeRun ExploreGeneratedMaze(uint64_t seed, const std::vector<std::string>& sets = {}) {
  MazeRun r;
  r.seed = seed;
  r.maze = sim::GenerateMaze(sim::MazeStyle{}, seed);
  const std::string dir = ::testing::TempDir() + "/generated_mazes";
  std::filesystem::create_directories(dir);
  const std::string arena = dir + "/maze_" + std::to_string(seed) + ".arena";
  std::ofstream(arena) << r.maze.ToArena();
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::string> all = {"source.path=" + arena};
  all.insert(all.end(), sets.begin(), sets.end());
  r.json = RunConfig("maze_explorer.ini", "generated_maze_" + std::to_string(seed), all, "score.json");
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

class MazeSample : public ::testing::TestWithParam<int> {};

TEST_P(MazeSample, ExploredMappedAndHomeWithoutCollision) {
  const MazeRun r = ExploreGeneratedMaze(GetParam());
  ExpectExploredMappedAndHome(r.json);
}
INSTANTIATE_TEST_SUITE_P(GeneratedMazes, MazeSample, ::testing::Values(6, 7, 9, 24, 64));

// Maze 27 with the lidar's measured range noise (2.2 cm, BENCHMARKS.md "The simulator fitted"): the
// map came out 1 % small, its far walls a cell inward (walls 0.938, coverage 0.982 on seed 1), while
// the refine's hit moments weighed every hit alike. With each hit weighing its range squared
// (`refine_range_power = 2`): walls 0.98, coverage 0.995; the bounds are what tell the two apart.
// The estimate's scale against the truth (least squares, as scripts/path_scale.py) is recorded,
// 0.9915 against 0.9898 before, and only bounded loosely: a closed loop moves with any change
// (with the corners held, 2026-12-05: 0.9922, walls 0.975, coverage 0.995). The noise is
// set here though it is now the simulator's default, so the test keeps it if the default moves.
TEST(MazeAtTheMeasuredNoise, Maze27IsMappedToScale) {
  const MazeRun r = ExploreGeneratedMaze(27, {"source.lidar_range_noise_m=0.022", "pipeline.seed=1"});
  ExpectExploredMappedAndHome(r.json);
  const std::string dir = ::testing::TempDir() + "/generated_maze_27";
  const auto estimate = TumXy(dir + "/slam.tum"), truth = TumXy(dir + "/ground_truth.tum");
  std::vector<std::complex<double>> a, b;
  for (const auto& [t, p] : estimate) {
    const auto it = truth.find(t);
    if (it == truth.end()) continue;
    a.emplace_back(p.first, p.second);
    b.emplace_back(it->second.first, it->second.second);
  }
  ASSERT_GT(a.size(), 500u);
  std::complex<double> ma, mb, num;
  for (size_t i = 0; i < a.size(); ++i) ma += a[i], mb += b[i];
  ma /= double(a.size()), mb /= double(a.size());
  double den = 0;
  for (size_t i = 0; i < a.size(); ++i) num += std::conj(a[i] - ma) * (b[i] - mb), den += std::norm(a[i] - ma);
  const double scale = den / std::abs(num);  // below 1: the estimated path, and its map, are small
  ::testing::Test::RecordProperty("estimate_scale", std::to_string(scale));
  EXPECT_GT(scale, 0.985);
  EXPECT_LT(scale, 1.01);
}

// config/maze_replay.ini runs the Maze Explorer's estimator (config/maze_slam.ini) on a recorded
// run (maze_1, recorded by an lcm_log output): its poses are the closed-loop run's, scan by scan, so
// an estimator change can be measured on the inputs that showed a problem.
TEST(MazeReplay, TheExplorersSlamOnItsOwnRecordingFollowsTheRun) {
  const std::string run = ::testing::TempDir() + "/maze_replay_run";
  const std::string json = RunConfig("maze_explorer.ini", "maze_replay_run",
                                     {"pipeline.outputs=rec", "rec.type=lcm_log", "rec.file=run.log"}, "score.json");
  ExpectExploredMappedAndHome(json);
  const std::string metrics =
      RunConfig("maze_replay.ini", "maze_replay_out", {"source.path=" + run + "/run.log"}, "metrics.json");
  ASSERT_FALSE(metrics.empty()) << "the replay wrote no metrics.json";
  const auto live = TumXy(run + "/slam.tum");
  const auto replay = TumXy(::testing::TempDir() + "/maze_replay_out/slam.tum");
  ASSERT_GT(live.size(), 300u);
  size_t paired = 0;
  double sum2 = 0, largest = 0;
  for (const auto& [t, p] : live) {
    const auto it = replay.find(t);
    if (it == replay.end()) continue;
    const double d = std::hypot(p.first - it->second.first, p.second - it->second.second);
    sum2 += d * d, largest = std::max(largest, d), ++paired;
  }
  EXPECT_GE(paired, live.size() * 99 / 100) << "scans of the run the replay did not place";
  const double rms = paired ? std::sqrt(sum2 / paired) : NAN;
  // Measured: 0.01 mm RMS, 0.06 mm at most (float stamps and message rounding); the replay without
  // refine_estimate differs by 19.5 mm RMS.
  EXPECT_LT(rms, 0.0005) << "replayed poses are not the run's";
  EXPECT_LT(largest, 0.002);
  ::testing::Test::RecordProperty("rms_m", std::to_string(rms));
  // The replay is scored against the recorded truth as any SLAM run is.
  EXPECT_LT(Get(metrics, {"slam_ate", "aligned", "xy_m", "rmse"}), 0.05);
}

}  // namespace
}  // namespace mbot::app
