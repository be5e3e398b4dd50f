// The Warehouse rules the mission and the referee share (apps/mbot_nav/stages/warehouse.hpp).
#include "stages/warehouse.hpp"

#include <gtest/gtest.h>

#include <set>

namespace mbot::app {
namespace {

drivers::World Warehouse() { return drivers::World::Load(std::string(MBOT_SOURCE_DIR) + "/datasets/arenas/warehouse.arena"); }

TEST(WarehouseRules, SevenDeliveriesToDistinctTargetsEachOnToADropOff) {
  const drivers::World w = Warehouse();
  const std::vector<warehouse::Stop> stops = warehouse::Stops(w, 1);
  ASSERT_EQ(warehouse::TotalDeliveries(), 7);
  ASSERT_EQ(stops.size(), 14u);
  std::set<int> targets;
  for (size_t k = 0; k < stops.size(); ++k) {
    EXPECT_EQ(stops[k].pickup, k % 2 == 0);
    EXPECT_EQ(stops[k].delivery, static_cast<int>(k / 2));
    if (stops[k].pickup) targets.insert(stops[k].arena_index);
    const auto& arena = w.PosesLabelled(stops[k].pickup ? "target" : "dropoff");
    EXPECT_EQ(stops[k].pose.x, arena.at(stops[k].arena_index).x);
  }
  EXPECT_EQ(targets.size(), 7u);
  EXPECT_EQ(stops[1].Name(), "drop-off 1 (delivery 1)");
}

TEST(WarehouseRules, TheSeedDecidesTheOrder) {
  const drivers::World w = Warehouse();
  auto order = [&](uint64_t seed) {
    std::vector<int> o;
    for (const auto& s : warehouse::Stops(w, seed)) o.push_back(s.arena_index);
    return o;
  };
  EXPECT_EQ(order(3), order(3));
  EXPECT_NE(order(3), order(4));
}

TEST(WarehouseRules, AnArenaWithoutEnoughTargetsIsNamed) {
  const drivers::World w = drivers::World::ParseArena("name tiny\nbox 0 0 2 2\npose target 1 1 0\npose dropoff 0.5 0.5 0\n", "tiny.arena");
  try {
    warehouse::Stops(w, 1);
    ADD_FAILURE();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("'tiny' needs 7 'pose target' lines"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mbot::app
