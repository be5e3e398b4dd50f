// The Maze Explorer event on a real botlab arena map as the simulator's world (center_maze.map from
// ../shared/datasets, unknown cells counted as walls): exploration from a corner, two seeds.
#include <gtest/gtest.h>

#include <cmath>

#include "run_config.hpp"

namespace mbot::app {
namespace {

class BotlabArena : public ::testing::TestWithParam<int> {};

TEST_P(BotlabArena, MazeExplorerMapsCenterMazeAndReturnsHomeWithoutCollision) {
  const int seed = GetParam();
  const std::string j = RunConfig("maze_explorer.ini", "botlab_center_maze_" + std::to_string(seed),
                                  {"pipeline.seed=" + std::to_string(seed),
                                   "source.path=${datasets}/botlab/mbot_example_logs_maps/center_maze.map",
                                   "source.start=-0.9, -0.6, 45"},  // the bottom-left corner, facing the middle
                                  "score.json");
  ASSERT_FALSE(j.empty());
  EXPECT_NE(j.find("\"completed\": true"), std::string::npos) << j;
  EXPECT_EQ(Get(j, {"collisions"}), 0);
  EXPECT_GE(Get(j, {"map", "coverage"}), 0.99);
  EXPECT_GE(Get(j, {"map", "wall_precision"}), 0.95);
  EXPECT_LE(std::hypot(Get(j, {"final_error", "x_m"}), Get(j, {"final_error", "y_m"})), 0.05);
  for (const char* k : {"time_s", "real_time_factor"}) RecordProperty(k, std::to_string(Get(j, {k})));
}
INSTANTIATE_TEST_SUITE_P(Seeds, BotlabArena, ::testing::Values(1, 2));

}  // namespace
}  // namespace mbot::app
