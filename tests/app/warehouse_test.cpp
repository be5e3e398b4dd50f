// The Warehouse rules the mission and the referee share (libs/mission/warehouse_rules.hpp), and the
// referee's judgement of the stops.
#include "mbot/mission/warehouse_rules.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "mbot/common/config.hpp"
#include "mbot/drivers/map_io.hpp"
#include "mbot/sim/world.hpp"
#include "mbot/mission/mission_config.hpp"
#include "stage.hpp"

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
  const sim::World w = sim::World::ParseArena("name tiny\nbox 0 0 2 2\npose target 1 1 0\npose dropoff 0.5 0.5 0\n", "tiny.arena");
  try {
    StopsOf(w, 1);
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("needs 7 targets and at least one drop-off (has 1 and 1)"), std::string::npos) << e.what();
  }
}

// The referee judges stops from the true pose: standing 2 s at a later stop marks the one before it
// missed, so that delivery fails while the next still counts (level 1 reached, level 2 not).
// Feeds a warehouse referee (seed 5) true poses at 100 Hz; Finish writes score.json.
class RefereeHarness {
 public:
  explicit RefereeHarness(const std::string& name) : out_(::testing::TempDir() + "/" + name) {
    auto c = config::Config::FromString("[referee]\ntype = referee\nevent = warehouse\ntime_limit_s = 720\n");
    config::Section section = c.GetSection("referee");
    referee_ = FindStageType("referee")->create(section);
    std::filesystem::create_directories(out_);
    ctx_ = RunContext{out_, 5, nullptr, std::string(MBOT_SOURCE_DIR) + "/datasets/arenas/warehouse.arena", nullptr};
    referee_->Start(ctx_);
  }
  void Stand(const motion::Pose2D& p, double seconds) {
    for (int i = 0; i < seconds * 100; ++i, t_ += 10'000) {
      referee_->OnEvent(drivers::Event{t_, t_, "TRUE_POSE", drivers::EventKind::kGroundTruth, p});
    }
  }
  // score.json, and its stop lines (line k + 1 is stop k).
  std::string Finish(std::vector<std::string>* lines) {
    referee_->Finish(ctx_, false);
    std::ifstream in(out_ + "/score.json");
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string j = ss.str();
    std::stringstream rows(j.substr(std::min(j.size(), j.find("\"stops\": ["))));
    for (std::string line; std::getline(rows, line);) lines->push_back(line);
    return j;
  }

 private:
  std::string out_;
  std::unique_ptr<Stage> referee_;
  RunContext ctx_;
  int64_t t_ = 0;
};

TEST(WarehouseReferee, AMissedStopFailsItsDeliveryAndTheNextStillCounts) {
  const auto stops = StopsOf(Warehouse(), 5);
  RefereeHarness h("warehouse_referee_missed");
  h.Stand(stops[0].pose, 2.2);                                  // target of delivery 1: done
  h.Stand({stops[1].pose.x + 0.3, stops[1].pose.y, 0}, 1.0);    // near its drop-off, but not at it
  h.Stand(stops[2].pose, 2.2);                                  // on to delivery 2: drop-off 1 missed
  h.Stand(stops[3].pose, 1.0);                                  // too short to count...
  h.Stand({0, 0, 0}, 0.01);
  h.Stand(stops[3].pose, 2.2);                                  // ...the second visit does
  std::vector<std::string> lines;
  const std::string j = h.Finish(&lines);
  EXPECT_NE(j.find("\"levels_reached\": 1,"), std::string::npos) << j;
  ASSERT_GE(lines.size(), 6u);
  EXPECT_NE(lines[1].find("\"missed\": false"), std::string::npos) << lines[1];  // target 1
  EXPECT_EQ(lines[1].find("\"done_at_s\": null"), std::string::npos) << lines[1];
  EXPECT_NE(lines[2].find("\"missed\": true"), std::string::npos) << lines[2];   // its drop-off
  EXPECT_NE(lines[3].find("\"missed\": false"), std::string::npos) << lines[3];
  EXPECT_NE(lines[4].find("\"missed\": false"), std::string::npos) << lines[4];
  EXPECT_EQ(lines[4].find("\"done_at_s\": null"), std::string::npos) << lines[4];
  EXPECT_NE(lines[5].find("\"done_at_s\": null, \"missed\": false"), std::string::npos) << lines[5];  // not reached
}

// The drop-offs repeat (stop 5 is drop-off 1 again): standing on at drop-off 1 after delivering to
// it does not count as the later visit, and does not mark the stops between missed.
TEST(WarehouseReferee, StayingAtADropOffDoesNotCountItsNextVisit) {
  const auto stops = StopsOf(Warehouse(), 5);
  ASSERT_EQ(stops[5].pose.x, stops[1].pose.x);
  RefereeHarness h("warehouse_referee_stay");
  h.Stand(stops[0].pose, 2.2);
  h.Stand(stops[1].pose, 6.0);
  std::vector<std::string> lines;
  h.Finish(&lines);
  ASSERT_GE(lines.size(), 7u);
  EXPECT_EQ(lines[2].find("\"done_at_s\": null"), std::string::npos) << lines[2];  // drop-off 1, delivery 1: done
  for (int k = 3; k <= 6; ++k) {
    EXPECT_NE(lines[k].find("\"done_at_s\": null, \"missed\": false"), std::string::npos) << lines[k];
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
  expect_same(s.waypoints, sim::EventInputsOf(sim::World::Load(dir + "/datasets/arenas/convex_circuit.arena")).waypoints,
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
