// The Maze Explorer event on real botlab arena maps as the simulator's world (center_maze.map and
// drive_maze.map from ../shared/datasets, the staff's SLAM maps: unknown cells are walls), from a
// corner and from the pose a map world starts at when it names none (the free pose with the most
// room), two seeds each. The referee's floor is what the robot's body reaches: drive_maze's walls
// have gaps narrower than the robot onto free space outside the maze (it scored 76 % coverage while
// that space counted).
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <string>
#include <tuple>

#include "competition.hpp"
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

// The Speed Run on a real arena map: a map names no circuit, so the competition's event section gives
// one (in the start's frame: the map's most-room pose), and the referee judges the lap as on an arena.
TEST(BotlabArena, SpeedRunDrivesAGivenCircuitOnCenterMaze) {
  auto c = config::Config::Load(std::string(MBOT_SOURCE_DIR) + "/config/competition.ini");
  const std::string out = ::testing::TempDir() + "/competition_speed_run_center_maze";
  std::filesystem::remove_all(out);
  c.Set("output.dir=" + out);
  c.Set("competition.events=speed_run");
  c.Set("speed_run.world=${datasets}/botlab/mbot_example_logs_maps/center_maze.map");
  // Without a circuit the event is refused, naming the map and how to give one.
  try {
    BuildCompetition(c);
    ADD_FAILURE() << "no error";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("give one with the event's waypoints = "), std::string::npos) << e.what();
  }
  c.Set("speed_run.waypoints=0.4, 0, 0; 0.4, 0.4, 90; -0.2, 0.4, 180; -0.2, 0, -90; 0, 0, 0");
  CompetitionPlan plan = BuildCompetition(c);
  std::atomic<bool> stop{false};
  RunCompetition(plan, stop);
  const std::string j = ReadReport(out + "/speed_run/score.json");
  ASSERT_FALSE(j.empty());
  EXPECT_NE(j.find("\"completed\": true"), std::string::npos) << j;
  EXPECT_EQ(Get(j, {"collisions"}), 0);
  EXPECT_LT(std::hypot(Get(j, {"final_error", "x_m"}), Get(j, {"final_error", "y_m"})), 0.05);
  ::testing::Test::RecordProperty("time_s", std::to_string(Get(j, {"time_s"})));
}

}  // namespace
}  // namespace mbot::app
