// The Warehouse rules the mission and the referee share (libs/mission/warehouse_rules.hpp), and the
// referee's judgement of the stops.
#include "mbot/mission/warehouse_rules.hpp"

#include <gtest/gtest.h>

#include <set>

#include "mbot/common/config.hpp"
#include "mbot/drivers/map_io.hpp"
#include "mbot/sim/world.hpp"
#include "mbot/mission/mission_config.hpp"

namespace mbot::app {
namespace {

namespace warehouse = mission::warehouse;

sim::World Warehouse() { return sim::World::Load(std::string(MBOT_SOURCE_DIR) + "/datasets/arenas/warehouse.arena"); }

std::vector<warehouse::Stop> StopsOf(const sim::World& w, uint64_t seed) {
  return warehouse::Stops(w.PosesLabelled("target"), w.PosesLabelled("dropoff"), seed);
}

TEST(WarehouseRules, SevenDeliveriesToDistinctTargetsEachOnToADropOff) {
  const sim::World w = Warehouse();
  const std::vector<warehouse::Stop> stops = StopsOf(w, 1);
  ASSERT_EQ(warehouse::TotalDeliveries(), 7);
  ASSERT_EQ(stops.size(), 14u);
  std::set<int> targets;
  for (size_t k = 0; k < stops.size(); ++k) {
    EXPECT_EQ(stops[k].pickup, k % 2 == 0);
    EXPECT_EQ(stops[k].delivery, static_cast<int>(k / 2));
    if (stops[k].pickup) targets.insert(stops[k].index);
    const auto& arena = w.PosesLabelled(stops[k].pickup ? "target" : "dropoff");
    EXPECT_EQ(stops[k].pose.x, arena.at(stops[k].index).x);
  }
  EXPECT_EQ(targets.size(), 7u);
  EXPECT_EQ(stops[1].Name(), "drop-off 1 (delivery 1)");
}

TEST(WarehouseRules, TheSeedDecidesTheOrder) {
  const sim::World w = Warehouse();
  auto order = [&](uint64_t seed) {
    std::vector<int> o;
    for (const auto& s : StopsOf(w, seed)) o.push_back(s.index);
    return o;
  };
  EXPECT_EQ(order(3), order(3));
  EXPECT_NE(order(3), order(4));
}

TEST(WarehouseRules, AnArenaWithoutEnoughTargetsIsNamed) {
  const sim::World w =
      sim::World::ParseArena("name tiny\nbox 0 0 2 2\npose target 1 1 0\npose dropoff 0.5 0.5 0\n", "tiny.arena");
  try {
    StopsOf(w, 1);
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("needs 7 targets and at least one drop-off (has 1 and 1)"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace mbot::app

namespace mbot::app {
namespace {

// The autonomy's inputs are its own keys (config/warehouse_day.ini, speed_run.ini): they must be
// what the shipped arenas hold, as the competition runner would hand them out.
TEST(DayInputs, TheShippedKeysAreTheShippedArenas) {
  const std::string dir = std::string(MBOT_SOURCE_DIR);
  auto mission_of = [&](const std::string& ini) {
    const config::Config c = config::Config::Load(dir + "/config/" + ini);
    config::Section s = c.GetSection("mission");
    return mission::ParseMissionOptions(s);
  };
  auto expect_same = [](const std::vector<motion::Pose2D>& a, const std::vector<motion::Pose2D>& b, const char* what) {
    ASSERT_EQ(a.size(), b.size()) << what;
    for (size_t i = 0; i < a.size(); ++i) {
      EXPECT_NEAR(a[i].x, b[i].x, 1e-9) << what << " " << i;
      EXPECT_NEAR(a[i].y, b[i].y, 1e-9) << what << " " << i;
      EXPECT_NEAR(motion::WrapAngle(a[i].theta - b[i].theta), 0.0, 1e-9) << what << " " << i;
    }
  };
  const sim::World warehouse = Warehouse();
  const sim::EventInputs day = sim::EventInputsOf(warehouse);
  const mission::MissionOptions w = mission_of("warehouse.ini");
  expect_same(w.targets, day.targets, "targets");
  expect_same(w.dropoffs, day.dropoffs, "drop-offs");
  const mission::MissionOptions s = mission_of("speed_run.ini");
  expect_same(s.waypoints,
              sim::EventInputsOf(sim::World::Load(dir + "/datasets/arenas/convex_circuit.arena")).waypoints,
              "waypoints");
  // The given map is the arena drawn at the SLAM resolution.
  std::string format;
  const mapping::OccupancyGrid shipped = drivers::ReadAnyMap(dir + "/datasets/arenas/warehouse.map", &format);
  const mapping::OccupancyGrid rendered = sim::RenderKnownMap(warehouse, 0.05);
  ASSERT_EQ(shipped.width(), rendered.width());
  ASSERT_EQ(shipped.height(), rendered.height());
  EXPECT_NEAR(shipped.origin_x(), rendered.origin_x(), 1e-9);
  EXPECT_NEAR(shipped.origin_y(), rendered.origin_y(), 1e-9);
  EXPECT_EQ(shipped.cells(), rendered.cells());
}

}  // namespace
}  // namespace mbot::app
