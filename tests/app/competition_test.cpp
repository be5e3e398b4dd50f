// The competition events in closed loop on the simulator (sim → SLAM → mission → sim), through the
// shipped configs, two seeds each, scored by the referee against the simulator's truth.
#include <gtest/gtest.h>

#include <cmath>

#include "../regression/run_config.hpp"

namespace mbot::app {
namespace {

class SpeedRun : public ::testing::TestWithParam<int> {};

TEST_P(SpeedRun, DrivesTheCircuitAndStopsWithin3cm3cm15DegWithoutCollision) {
  const int seed = GetParam();
  const std::string j = RunConfig("speed_run.ini", "speed_run_" + std::to_string(seed),
                                  {"pipeline.seed=" + std::to_string(seed)}, "score.json");
  ASSERT_FALSE(j.empty());
  EXPECT_NE(j.find("\"completed\": true"), std::string::npos) << j;
  EXPECT_EQ(Get(j, {"collisions"}), 0);
  EXPECT_LT(Get(j, {"final_error", "x_m"}), 0.03);
  EXPECT_LT(Get(j, {"final_error", "y_m"}), 0.03);
  EXPECT_LT(Get(j, {"final_error", "theta_deg"}), 15.0);
  EXPECT_GE(Get(j, {"map", "coverage"}), 0.99);
  for (const char* k : {"time_s", "real_time_factor"}) RecordProperty(k, std::to_string(Get(j, {k})));
}
INSTANTIATE_TEST_SUITE_P(Seeds, SpeedRun, ::testing::Values(1, 2));

class MazeExplorer : public ::testing::TestWithParam<int> {};

TEST_P(MazeExplorer, MapsTheReachableSpaceAndReturnsHomeWithoutCollision) {
  const int seed = GetParam();
  const std::string j = RunConfig("maze_explorer.ini", "maze_explorer_" + std::to_string(seed),
                                  {"pipeline.seed=" + std::to_string(seed)}, "score.json");
  ASSERT_FALSE(j.empty());
  EXPECT_NE(j.find("\"completed\": true"), std::string::npos) << j;
  EXPECT_EQ(Get(j, {"collisions"}), 0);
  EXPECT_GE(Get(j, {"map", "coverage"}), 0.99);
  EXPECT_GE(Get(j, {"map", "wall_precision"}), 0.95);
  EXPECT_LE(std::hypot(Get(j, {"final_error", "x_m"}), Get(j, {"final_error", "y_m"})), 0.05);
  for (const char* k : {"time_s", "real_time_factor"}) RecordProperty(k, std::to_string(Get(j, {k})));
}
INSTANTIATE_TEST_SUITE_P(Seeds, MazeExplorer, ::testing::Values(1, 2));

// Ctrl-C in the middle of an event (a stage raises the flag the signal handler would, after 8,000
// events, ~22 s into the maze): the map, the trajectories and the score are still written.
class StopAfter : public Stage {
 public:
  StopAfter(std::atomic<bool>* stop, long long n) : stop_(stop), n_(n) {}
  void OnEvent(const drivers::Event&) override {
    if (++seen_ >= n_) *stop_ = true;
  }
  void Finish(const RunContext&, bool) override {}

 private:
  std::atomic<bool>* stop_;
  long long n_, seen_ = 0;
};

TEST(MazeExplorer, InterruptedRunStillWritesMapTrajectoriesAndScore) {
  auto c = config::Config::Load(std::string(MBOT_SOURCE_DIR) + "/config/maze_explorer.ini");
  const std::string out = ::testing::TempDir() + "/maze_interrupted";
  std::filesystem::remove_all(out);
  c.Set("output.dir=" + out);
  c.Set("pipeline.progress=off");
  auto plan = BuildPlan(c);
  std::atomic<bool> stop{false};
  plan.stages.emplace_back("stop_after", std::make_unique<StopAfter>(&stop, 8000));
  const RunSummary summary = RunPlan(plan, stop);
  EXPECT_TRUE(summary.interrupted);
  std::ifstream in(out + "/score.json");
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_NE(ss.str().find("\"interrupted\": true"), std::string::npos) << ss.str();
  EXPECT_NE(ss.str().find("\"completed\": false"), std::string::npos);
  for (const char* f : {"final_map.png", "final_map.map", "true_path.tum", "slam_path.tum", "mission.json"}) {
    EXPECT_GT(std::filesystem::file_size(out + "/" + f), 0u) << f;
  }
}

}  // namespace
}  // namespace mbot::app
