// The competition events in closed loop on the simulator (sim → SLAM → mission → sim), through the
// shipped configs, two seeds each, scored by the referee against the simulator's truth.
#include <gtest/gtest.h>

#include <cmath>
#include <tuple>

#include "../regression/run_config.hpp"
#include "competition.hpp"
#include "mbot/sim/sim_source_options.hpp"

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

class MazeExplorer : public ::testing::TestWithParam<std::tuple<std::string, int>> {};

TEST_P(MazeExplorer, MapsTheReachableSpaceAndReturnsHomeWithoutCollision) {
  const auto& [arena, seed] = GetParam();
  const std::string j =
      RunConfig("maze_explorer.ini", "maze_explorer_" + arena + "_" + std::to_string(seed),
                {"pipeline.seed=" + std::to_string(seed),
                 "source.path=" + std::string(MBOT_SOURCE_DIR) + "/datasets/arenas/" + arena + ".arena"},
                "score.json");
  ExpectExploredMappedAndHome(j);
}
INSTANTIATE_TEST_SUITE_P(ArenasAndSeeds, MazeExplorer,
                         ::testing::Combine(::testing::Values("maze_1", "maze_2", "maze_3"), ::testing::Values(1, 2)),
                         [](const auto& info) {
                           return std::get<0>(info.param) + "_seed" + std::to_string(std::get<1>(info.param));
                         });

class Warehouse : public ::testing::TestWithParam<int> {};

// A random start in the known map (seeded), global localization, then all seven deliveries: the
// referee judges each stop from the true pose (within 0.08 m and 15 deg for 2 s, in order).
TEST_P(Warehouse, LocalizesGloballyAndReachesLevel3InTimeWithoutCollision) {
  const int seed = GetParam();
  const std::string j = RunConfig("warehouse.ini", "warehouse_" + std::to_string(seed),
                                  {"pipeline.seed=" + std::to_string(seed)}, "score.json");
  ASSERT_FALSE(j.empty());
  EXPECT_NE(j.find("\"completed\": true"), std::string::npos) << j;
  EXPECT_EQ(Get(j, {"collisions"}), 0);
  EXPECT_EQ(Get(j, {"levels_reached"}), 3) << j;
  EXPECT_LT(Get(j, {"time_s"}), 720.0);
  EXPECT_LT(Get(j, {"localized_at_s"}), 10.0);
  EXPECT_LT(std::hypot(Get(j, {"slam_final_error", "x_m"}), Get(j, {"slam_final_error", "y_m"})), 0.05);
  for (const char* k : {"time_s", "localized_at_s", "real_time_factor"}) RecordProperty(k, std::to_string(Get(j, {k})));
}
INSTANTIATE_TEST_SUITE_P(Seeds, Warehouse, ::testing::Values(1, 2));

class HeavyLift : public ::testing::TestWithParam<std::tuple<int, int>> {};

// The first 1, 2 or 3 of the day's assignments: every crate found by its tag, lifted and stacked on
// its crate (the referee judges from the simulator's crates), home, no collision.
TEST_P(HeavyLift, LiftsAndStacksEveryCrateWithoutCollision) {
  const auto& [crates, seed] = GetParam();
  const char* stacks[] = {"1:11", "1:11, 2:12", "1:11, 2:12, 3:13"};
  const std::string j =
      RunConfig("heavy_lift.ini", "heavy_lift_" + std::to_string(crates) + "_" + std::to_string(seed),
                {"pipeline.seed=" + std::to_string(seed), "mission.stack=" + std::string(stacks[crates - 1]),
                 "referee.crates=" + std::to_string(crates)},
                "score.json");
  ASSERT_FALSE(j.empty());
  EXPECT_NE(j.find("\"completed\": true"), std::string::npos) << j;
  EXPECT_EQ(Get(j, {"collisions"}), 0) << j;
  EXPECT_EQ(Get(j, {"points", "total"}), 100 * crates) << j;
  EXPECT_EQ(Get(j, {"points", "max"}), 100 * crates);
  for (const char* k : {"time_s", "real_time_factor"}) RecordProperty(k, std::to_string(Get(j, {k})));
}
INSTANTIATE_TEST_SUITE_P(CratesAndSeeds, HeavyLift,
                         ::testing::Combine(::testing::Values(1, 2, 3), ::testing::Values(1, 2)), [](const auto& info) {
                           return std::to_string(std::get<0>(info.param)) + "_crates_seed" +
                                  std::to_string(std::get<1>(info.param));
                         });

// Ctrl-C in the middle of an event (a stage raises the flag the signal handler would, after 8,000
// events, ~22 s into the maze): the map, the trajectories and the score are still written.
class StopAfter : public Stage {
 public:
  StopAfter(std::atomic<bool>* stop, long long n) : stop_(stop), n_(n) {}
  void OnEvent(const msgs::Event&) override {
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
  auto plan = pipeline::BuildPlan(c);
  std::atomic<bool> stop{false};
  plan.stages.emplace_back("stop_after", std::make_unique<StopAfter>(&stop, 8000));
  const pipeline::RunSummary summary = pipeline::RunPlan(plan, stop);
  EXPECT_TRUE(summary.interrupted);
  const std::string score = ReadReport(out + "/score.json");
  EXPECT_NE(score.find("\"interrupted\": true"), std::string::npos) << score;
  EXPECT_NE(score.find("\"completed\": false"), std::string::npos);
  for (const char* f : {"final_map.png", "final_map.map", "true_path.tum", "slam_path.tum", "mission.json"}) {
    EXPECT_GT(std::filesystem::file_size(out + "/" + f), 0u) << f;
  }
}

// A simulated run recorded by an `lcm_log` output replays through the LCM log source like a robot's
// log: the same scans, and SLAM on the replay as accurate as it was live (a replay is its own SLAM
// run with the same seed, so the figures agree within noise, not to the bit).
TEST(Recording, ASimulatedRunReplaysThroughTheLogSource) {
  const std::string live = RunConfig("speed_run.ini", "recorded_speed_run",
                                     {"pipeline.outputs=record", "record.type=lcm_log"}, "metrics.json");
  ASSERT_FALSE(live.empty());
  const std::string log = ::testing::TempDir() + "/recorded_speed_run/recording.log";
  ASSERT_TRUE(std::filesystem::exists(log));
  const std::string out = ::testing::TempDir() + "/recorded_speed_run_replay";
  std::filesystem::remove_all(out);
  auto c = config::Config::FromString(
      "include = defaults.ini\n[pipeline]\nstages = slam\nprogress = off\n[source]\npath = " + log +
          "\n[output]\ndir = " + out +
          "\n[slam]\ntype = slam\nmode = full_slam\nparticles = 300\ninitial_pose = origin\n",
      "replay.ini", std::string(MBOT_SOURCE_DIR) + "/config");
  auto plan = pipeline::BuildPlan(c);
  std::atomic<bool> stop{false};
  pipeline::RunPlan(plan, stop);
  const std::string replay = ReadReport(out + "/metrics.json");
  ASSERT_FALSE(replay.empty());
  EXPECT_EQ(Get(replay, {"scans"}), Get(live, {"scans"}));
  EXPECT_EQ(Get(replay, {"scans_skipped"}), 0);
  EXPECT_LT(Get(replay, {"slam_ate", "aligned", "xy_m", "rmse"}), 0.02);
  EXPECT_NEAR(Get(replay, {"slam_ate", "aligned", "xy_m", "rmse"}), Get(live, {"slam_ate", "aligned", "xy_m", "rmse"}),
              0.01);
}

// The README's first command: config/competition.ini runs the four events with one seed and writes
// one table.
TEST(Competition, RunsEveryEventAndWritesOneTable) {
  auto c = config::Config::Load(std::string(MBOT_SOURCE_DIR) + "/config/competition.ini");
  const std::string out = ::testing::TempDir() + "/competition";
  std::filesystem::remove_all(out);
  c.Set("output.dir=" + out);
  CompetitionPlan plan = BuildCompetition(c);
  ASSERT_EQ(plan.events.size(), 4u);
  std::atomic<bool> stop{false};
  EXPECT_EQ(RunCompetition(plan, stop), 0);
  const std::string j = ReadReport(out + "/competition.json");
  for (const char* e : {"Speed Run", "Maze Explorer", "Warehouse", "Heavy Lift"})
    EXPECT_NE(j.find(e), std::string::npos) << j;
  EXPECT_NE(j.find("\"not_run\": []"), std::string::npos) << j;
  EXPECT_EQ(Get(j, {"not_run", "max_points"}), 1300);  // 300 + 300 + 400 + 300
  EXPECT_GE(Get(j, {"not_run", "points"}), 1200) << j;
  EXPECT_NE(j.find("\"complete\": true"), std::string::npos) << j;
  for (const char* e : {"speed_run", "maze_explorer", "warehouse", "heavy_lift"}) {
    for (const char* f : {"score.json", "final_map.png", "true_path.tum", "slam_path.tum"}) {
      EXPECT_TRUE(std::filesystem::exists(out + "/" + e + "/" + f)) << e << "/" << f;
    }
  }
}

TEST(Competition, ConfigErrorsNameTheSectionAndKeyBeforeAnythingRuns) {
  const std::string dir = std::string(MBOT_SOURCE_DIR) + "/config";
  auto expect_error = [&](const std::string& text, const std::string& what) {
    try {
      BuildCompetition(config::Config::FromString(text, "bad.ini", dir));
      ADD_FAILURE() << "no error for: " << text;
    } catch (const config::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  expect_error("[competition]\nevents = speed_run\n", "event 'speed_run' has no [speed_run] section");
  expect_error(
      "[competition]\nevents = speed_run\n[speed_run]\nconfig = " + dir + "/speed_run.ini\n[maze]\nworld = x\n",
      "[maze] is not used");
  expect_error(
      "[competition]\nevents = speed_run\n[speed_run]\nconfig = " + dir + "/speed_run.ini\nworld = nowhere.arena\n",
      "[speed_run] world: nowhere.arena: no such file");
  expect_error("[competition]\nevents = speed_run\n[speed_run]\nconfig = " + dir +
                   "/speed_run.ini\nset = mission.max_sped_m_s=1\n",
               "[speed_run] (config = " + dir +
                   "/speed_run.ini, with this section's seed, world and set): --set: [mission] max_sped_m_s");
  expect_error("[competition]\nevents = speed_run\n[speed_run]\n", "[speed_run] config: required");
  expect_error("[competition]\nevents = speed_run\n[speed_run]\nconfig = nowhere.ini\n",
               "[speed_run] config: nowhere.ini");
}

// One event of the competition, a world with a comma-separated start and several overrides.
TEST(Competition, RunsTheListedEventsOnlyWithOverrides) {
  auto c = config::Config::Load(std::string(MBOT_SOURCE_DIR) + "/config/competition.ini");
  c.Set("output.dir=" + ::testing::TempDir() + "/competition_one");
  c.Set("competition.events=maze_explorer");
  c.Set("maze_explorer.world=" + std::string(MBOT_SOURCE_DIR) + "/datasets/arenas/maze_2.arena");
  c.Set("maze_explorer.set=source.start=0, 0, 90; mission.max_speed_m_s=0.25");
  CompetitionPlan plan = BuildCompetition(c);
  ASSERT_EQ(plan.events.size(), 1u);
  EXPECT_EQ(std::any_cast<const sim::SimSourceOptions&>(plan.events[0].plan.source.extra).start->theta, M_PI / 2);
  EXPECT_NE(plan.events[0].plan.source.path.find("maze_2.arena"), std::string::npos);
}

}  // namespace
}  // namespace mbot::app
