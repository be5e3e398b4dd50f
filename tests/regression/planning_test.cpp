// Planning on the real botlab maps: the A* regression through the app (config/astar_test.ini) and
// exploration of the real arena maps around a scripted robot.
#include <gtest/gtest.h>

#include <atomic>
#include <sstream>

#include "../planning/exploration_sim.hpp"
#include "mbot/common/config.hpp"
#include "mbot/drivers/map_io.hpp"
#include "mbot/pipeline/pipeline.hpp"

namespace mbot::planning {
namespace {

std::string Data(const std::string& rel) { return config::DatasetsDir() + "/" + rel; }

TEST(PlanningRegressionTest, BotlabAStarCasesAllPassThroughTheShippedConfig) {
  auto cfg = config::Config::Load(std::string(MBOT_SOURCE_DIR) + "/config/astar_test.ini");
  cfg.Set("output.dir=" + ::testing::TempDir() + "/astar_test");
  cfg.Set("astar.repeats=3");
  cfg.Set("pipeline.progress=off");
  pipeline::PipelinePlan plan = pipeline::BuildPlan(cfg);
  std::atomic<bool> stop{false};
  ::testing::internal::CaptureStdout();
  EXPECT_NO_THROW(pipeline::RunPlan(plan, stop));  // throws when any map fails
  const std::string out = ::testing::internal::GetCapturedStdout();
  for (const char* map : {"convex", "empty", "filled", "maze", "narrow", "wide"}) {
    EXPECT_NE(out.find(std::string(map) + std::string(10 - std::string(map).size() + 1, ' ') + "PASSED"),
              std::string::npos)
        << map << "\n"
        << out;
  }
}

struct ArenaCase {
  const char* map;
  motion::Pose2D home;
};

class ExplorationRegressionTest : public ::testing::TestWithParam<ArenaCase> {};

// True when a cell unknown in the truth lies within radius_m of (x, y).
bool NearUnknownTruth(const mapping::OccupancyGrid& truth, double x, double y, double radius_m) {
  int cx, cy;
  truth.WorldToCell(x, y, &cx, &cy);
  const int r = static_cast<int>(std::ceil(radius_m / truth.resolution()));
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      if (truth.IsInside(cx + dx, cy + dy) && truth.at(cx + dx, cy + dy) == 0) return true;
    }
  }
  return false;
}

// The explorer maps every reachable region of a real botlab arena and returns home, never
// driving within the robot radius of a wall.
TEST_P(ExplorationRegressionTest, ExploresTheArenaAndReturnsHome) {
  const ArenaCase& c = GetParam();
  const mapping::OccupancyGrid truth = drivers::ReadBotlabMap(Data(c.map));
  ExplorationOptions o;
  const testing::ScriptedRun run = testing::RunScripted(truth, c.home, o, 1.5, 3000);
  std::ostringstream facts;
  facts << c.map << ": state " << ToString(run.final_state) << " (" << run.reason << "), coverage " << run.coverage
        << ", driven " << run.driven_m << " m, " << run.paths << " paths, " << run.updates << " updates, min clearance "
        << run.min_true_clearance_m;
  std::cout << facts.str() << "\n";
  // These maps were made from real logs and hold unknown space of their own (gaps in the walls,
  // unseen corners) that the scripted sensor cannot see into: frontiers there stay, and the honest
  // end is "incomplete" with each of them placed beside such space. Everything reachable is mapped.
  if (run.final_state == ExplorationState::kIncomplete) {
    ASSERT_FALSE(run.left.empty()) << facts.str();
    for (const FrontierLeft& f : run.left) {
      EXPECT_TRUE(NearUnknownTruth(truth, f.x, f.y, 0.5))
          << "a frontier left at (" << f.x << ", " << f.y << ") has no unseeable space near it; " << facts.str();
    }
  } else {
    EXPECT_EQ(run.final_state, ExplorationState::kCompleted) << facts.str();
  }
  EXPECT_GE(run.coverage, 0.99) << facts.str();
  EXPECT_LE(std::hypot(run.final_pose.x - c.home.x, run.final_pose.y - c.home.y), 0.03) << facts.str();
  EXPECT_GT(run.min_true_clearance_m, o.astar.robot_radius_m) << facts.str();
}

INSTANTIATE_TEST_SUITE_P(BotlabArenas, ExplorationRegressionTest,
                         ::testing::Values(ArenaCase{"botlab/astar/maze.map", {0.0, 0.0, 0.0}},
                                           ArenaCase{"botlab/mbot_example_logs_maps/drive_maze.map", {0.0, 0.0, 0.0}},
                                           ArenaCase{"botlab/mbot_example_logs_maps/center_maze.map", {0.0, 0.0, 0.0}},
                                           ArenaCase{"botlab/mbot_example_logs_maps/drive_square.map",
                                                     {0.0, 0.0, 0.0}}),
                         [](const auto& info) {
                           std::string n = info.param.map;
                           n = n.substr(n.rfind('/') + 1);
                           return n.substr(0, n.find('.'));
                         });

}  // namespace
}  // namespace mbot::planning
