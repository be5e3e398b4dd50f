// The Maze Explorer event on real botlab arena maps as the simulator's world (center_maze.map and
// drive_maze.map from ../shared/datasets, the staff's SLAM maps: unknown cells are walls), from a
// corner and from the pose a map world starts at when it names none (the free pose with the most
// room), two seeds each. The referee's floor is what the robot's body reaches: drive_maze's walls
// have gaps narrower than the robot onto free space outside the maze (it scored 76 % coverage while
// that space counted).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <tuple>

#include "run_config.hpp"

namespace mbot::app {
namespace {

class BotlabArena : public ::testing::TestWithParam<std::tuple<std::string, std::string, int>> {};

TEST_P(BotlabArena, MazeExplorerMapsTheArenaAndReturnsHomeWithoutCollision) {
  const auto& [map, start, seed] = GetParam();
  std::vector<std::string> sets = {"pipeline.seed=" + std::to_string(seed),
                                   "source.path=${datasets}/botlab/mbot_example_logs_maps/" + map + ".map"};
  if (!start.empty()) sets.push_back("source.start=" + start);
  const std::string j =
      RunConfig("maze_explorer.ini", "botlab_" + map + (start.empty() ? "_room_" : "_") + std::to_string(seed), sets,
                "score.json");
  ExpectExploredMappedAndHome(j);
}
INSTANTIATE_TEST_SUITE_P(
    MapsStartsAndSeeds, BotlabArena,
    ::testing::Values(std::make_tuple("center_maze", "-0.9, -0.6, 45", 1),  // a corner, facing the middle
                      std::make_tuple("center_maze", "-0.9, -0.6, 45", 2), std::make_tuple("center_maze", "", 1),
                      std::make_tuple("drive_maze", "", 1), std::make_tuple("drive_maze", "", 2)),
    [](const auto& info) {
      return std::get<0>(info.param) + (std::get<1>(info.param).empty() ? "_most_room" : "_corner") + "_seed" +
             std::to_string(std::get<2>(info.param));
    });

}  // namespace
}  // namespace mbot::app
