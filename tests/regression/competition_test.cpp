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
  const std::string j = RunConfig(
      "maze_explorer.ini", "botlab_center_maze_" + std::to_string(seed),
      {"pipeline.seed=" + std::to_string(seed), "source.path=${datasets}/botlab/mbot_example_logs_maps/center_maze.map",
       "source.start=-0.9, -0.6, 45"},  // the bottom-left corner, facing the middle
      "score.json");
  ExpectExploredMappedAndHome(j);
}
INSTANTIATE_TEST_SUITE_P(Seeds, BotlabArena, ::testing::Values(1, 2));

}  // namespace
}  // namespace mbot::app
