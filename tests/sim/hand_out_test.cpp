// What the organisers hand out for another world, as settings of the event's configuration.
#include "mbot/sim/hand_out.hpp"

#include <gtest/gtest.h>

#include "mbot/drivers/map_io.hpp"

namespace mbot::sim {
namespace {

World Arena(const std::string& name) { return World::Load(std::string(MBOT_SOURCE_DIR) + "/datasets/arenas/" + name); }

TEST(HandOut, TheCircuitInTheStartFrameForAWaypointsTask) {
  const std::vector<std::string> sets =
      HandOut(Arena("convex_circuit.arena"), "convex", {"waypoints", false, 0.05}, "");
  ASSERT_EQ(sets.size(), 1u);
  EXPECT_EQ(sets[0].rfind("mission.waypoints=0.7, 0, 22.5; 1.075, 0.375, 67.5;", 0), 0u) << sets[0];
}

TEST(HandOut, TheWarehousesPosesAndItsKnownMapForLocalization) {
  const World w = Arena("warehouse.arena");
  const std::string map = ::testing::TempDir() + "/hand_out/known.map";
  const std::vector<std::string> sets = HandOut(w, "warehouse", {"warehouse", true, 0.05}, map);
  ASSERT_EQ(sets.size(), 3u);
  EXPECT_EQ(sets[0].rfind("mission.targets=0.9, 0, 90; 2.7, 0, 90;", 0), 0u) << sets[0];
  EXPECT_EQ(sets[1], "mission.dropoffs=0, 1.8, 180; 3.585, 1.8, 0");
  EXPECT_EQ(sets[2], "slam.map_file=" + map);
  EXPECT_EQ(drivers::ReadAnyMap(map).cells(), RenderKnownMap(w, 0.05).cells());
}

TEST(HandOut, AWorldWithoutWhatTheTaskNeedsIsNamed) {
  try {
    HandOut(Arena("maze_1.arena"), "maze_1.arena", {"warehouse", false, 0.05}, "");
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("maze_1.arena has no 'pose target'"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(HandOut(Arena("maze_1.arena"), "maze_1", {"explore", false, 0.05}, "").empty());
}

}  // namespace
}  // namespace mbot::sim
