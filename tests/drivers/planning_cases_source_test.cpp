#include "planning_cases_source.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "mbot/drivers/map_io.hpp"
#include "mbot/drivers/source_options.hpp"
#include "test_util.hpp"

namespace mbot::drivers {

using namespace msgs;  // the event vocabulary
namespace {

void WriteText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

std::string BotlabFixture(const std::string& dir_name, const std::string& poses) {
  const std::string dir = test::TempPath(dir_name);
  std::filesystem::create_directories(dir);
  WriteBotlabMap(msgs::OccupancyGrid(20, 10, 0.05, -0.5, -0.25, -100), dir + "/room.map");
  WriteText(dir + "/room_poses.txt", poses);
  return dir;
}

TEST(PlanningCasesSourceTest, BotlabCasesFollowTheirMap) {
  const std::string dir = BotlabFixture("cases_ok", "2\n0 0 0.3 0.1 1\n-0.4 0 0.4 0 0\n");
  EXPECT_EQ(DetectFormat(dir), "astar_cases");
  EXPECT_EQ(DetectFormat(dir + "/room_poses.txt"), "astar_cases");
  PlanningCasesSource src(dir, "astar_cases");
  auto map = src.Next();
  ASSERT_TRUE(map);
  EXPECT_EQ(map->kind, EventKind::kMap);
  EXPECT_EQ(map->channel, "room");
  auto c0 = src.Next();
  ASSERT_TRUE(c0);
  ASSERT_EQ(c0->kind, EventKind::kPlanRequest);
  const auto& r = std::get<PlanRequest>(c0->payload);
  EXPECT_EQ(r.goal.x, 0.3);
  EXPECT_EQ(r.expect_path, 1);
  EXPECT_EQ(std::get<PlanRequest>(src.Next()->payload).expect_path, 0);
  EXPECT_FALSE(src.Next());
  EXPECT_EQ(src.Progress(), 1.0);
}

TEST(PlanningCasesSourceTest, MalformedCasesNameFileAndLine) {
  const std::string dir = BotlabFixture("cases_bad", "2\n0 0 0.3 0.1 1\n0 0 0.3 x 1\n");
  try {
    PlanningCasesSource src(dir + "/room_poses.txt", "astar_cases");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("room_poses.txt:3: expected"), std::string::npos) << e.what();
  }
  const std::string short_dir = BotlabFixture("cases_short", "3\n0 0 0.3 0.1 1\n");
  EXPECT_THROW(PlanningCasesSource(short_dir, "astar_cases"), std::runtime_error);
}

TEST(PlanningCasesSourceTest, MovingAiScenariosFlipRowsAndFindTheirMap) {
  const std::string root = test::TempPath("mai");
  std::filesystem::create_directories(root + "/maps/set");
  std::filesystem::create_directories(root + "/scenarios/set");
  WriteText(root + "/maps/set/tiny.map", "type octile\r\nheight 3\r\nwidth 4\r\nmap\r\n....\r\n.@@.\r\n....\r\n");
  WriteText(root + "/scenarios/set/tiny.map.scen", "version 1\n0\tmaps/set/tiny.map\t4\t3\t0\t0\t3\t2\t3.82842712\n\n");
  const std::string scen = root + "/scenarios/set/tiny.map.scen";
  EXPECT_EQ(DetectFormat(scen), "movingai");
  PlanningCasesSource src(scen, "movingai");
  auto map = src.Next();
  ASSERT_TRUE(map);
  const auto& grid = *std::get<std::shared_ptr<const msgs::OccupancyGrid>>(map->payload);
  EXPECT_GT(grid.at(1, 1), 0);                                       // the '@' row is the middle one either way
  const PlanRequest r = std::get<PlanRequest>(src.Next()->payload);  // a copy: the event is a temporary
  EXPECT_EQ(r.start.x, 0.5);
  EXPECT_EQ(r.start.y, 2.5);  // Moving AI row 0 is the top: grid row 2
  EXPECT_EQ(r.goal.y, 0.5);
  EXPECT_NEAR(r.optimal_length_m, 3.82842712, 1e-9);
  EXPECT_FALSE(src.Next());

  WriteText(root + "/scenarios/set/wrong.map.scen", "version 1\n0\tmaps/set/tiny.map\t5\t3\t0\t0\t3\t2\t3\n");
  EXPECT_THROW(PlanningCasesSource(root + "/scenarios/set/wrong.map.scen", "movingai"), std::runtime_error);
}

}  // namespace
}  // namespace mbot::drivers
