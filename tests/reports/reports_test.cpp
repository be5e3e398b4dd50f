// The JSON reports through the library: written whole, read back with the same library, numbers
// to 6 significant digits and non-finite ones as null, keys in the order the report gives them.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "mbot/reports/competition_report.hpp"
#include "mbot/reports/json.hpp"
#include "mbot/reports/mission_report.hpp"
#include "mbot/reports/score.hpp"

namespace mbot::reports {
namespace {

TEST(Reports, NumbersKeepSixSignificantDigitsAndNonFiniteOnesAreNull) {
  EXPECT_EQ(Number(0.123456789).dump(), "0.123457");
  EXPECT_EQ(Number(14.07).dump(), "14.07");
  EXPECT_EQ(Number(NAN).dump(), "null");
  EXPECT_EQ(Number(INFINITY).dump(), "null");
  EXPECT_EQ(Number(1234.5678, 4).dump(), "1235.0");
}

TEST(Reports, AScoreIsWrittenWholeAndReadsBack) {
  sim::Score s;
  s.event = sim::CompetitionEvent::kHeavyLift;
  s.state = msgs::MissionState::kCompleted;
  s.completed = true;
  s.time_s = 146.1;
  s.sim_s = 150;
  s.final_error = sim::PoseError{0.01, 0.02, 1.5};
  s.crates.push_back({1, 11, true, true, false, {0.5, 0.25, 0.1}, 0.12});
  s.items = {{"lift crate 1", "lifted", 50, 50}, {"stack crate 1 on 11", "on 11", 50, 50}};
  s.total = 100, s.max_total = 100;
  s.collisions = 2;
  s.collision_events = {{12.5, {1.0, 2.0, 0.5}, motion::Pose2D{1.03, 2.04, 0.5}, 0.1, 0.05},
                        {20.0, {0.5, 0.5, 0.0}, std::nullopt, 0.0}};
  const std::string path = ::testing::TempDir() + "/score_report.json";
  WriteJson(path, ScoreReport(s, {"worlds/heavy_lift.arena", "heavy_lift", 3, false, 10.0}));
  const Json j = ReadJson(path);
  EXPECT_EQ(j["event"], "heavy_lift");
  EXPECT_EQ(j["state"], "completed");
  EXPECT_EQ(j["seed"], 3);
  EXPECT_DOUBLE_EQ(j["real_time_factor"].get<double>(), 15.0);
  EXPECT_DOUBLE_EQ(j["final_error"]["theta_deg"].get<double>(), 1.5);
  ASSERT_EQ(j["crates"].size(), 1u);
  EXPECT_EQ(j["crates"][0]["on"], 11);
  EXPECT_TRUE(j["crates"][0]["stacked"].get<bool>());
  EXPECT_EQ(j["points"]["lift crate 1"], 50);
  EXPECT_EQ(j["points"]["total"], 100);
  ASSERT_EQ(j["collision_events"].size(), 2u);
  EXPECT_DOUBLE_EQ(j["collision_events"][0]["t_s"].get<double>(), 12.5);
  EXPECT_DOUBLE_EQ(j["collision_events"][0]["pose"]["y"].get<double>(), 2.0);
  EXPECT_DOUBLE_EQ(j["collision_events"][0]["estimate_error_m"].get<double>(), 0.05);
  EXPECT_FALSE(j["collision_events"][1].contains("estimate"));  // SLAM had published nothing yet
  EXPECT_FALSE(j.contains("stops"));                            // the Warehouse's only
  EXPECT_EQ(j.begin().key(), "event");                          // the report's order, not the alphabet's
  const std::string text = RubricText(s, {"", "heavy_lift", 3, false, 10.0});
  EXPECT_NE(text.find("completed after 146.1 s"), std::string::npos);
  EXPECT_NE(
      text.find("collision at 12.5 s, true pose (1, 2) m, SLAM's estimate 0.1 s before it 0.05 m off the truth then"),
      std::string::npos)
      << text;
}

TEST(Reports, AnUnreadableReportIsNamed) {
  const std::string path = ::testing::TempDir() + "/broken_report.json";
  std::ofstream(path) << "{\"event\": ";
  try {
    ReadJson(path);
    FAIL() << "a cut-off report was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path + ": not valid JSON"), std::string::npos) << e.what();
  }
}

TEST(Reports, TheCompetitionTableSumsTheScoredEventsAndSaysWhenOneIsMissing) {
  std::vector<CompetitionRow> rows(2);
  rows[0] = {"speed_run", "completed", "out/speed_run",
             msgs::EventResult{"Speed Run", "convex circuit", 1, "completed", 14.07, 191, 300, 300, 0}};
  rows[1] = {"warehouse", "error: no world", "out/warehouse", std::nullopt};
  const Json j = CompetitionJson(rows, {"Heavy Lift: not today"});
  EXPECT_EQ(j["points"], 300);
  EXPECT_FALSE(j["complete"].get<bool>());
  EXPECT_TRUE(j["events"][1]["points"].is_null());
  EXPECT_EQ(j["not_run"][0], "Heavy Lift: not today");
  const std::string table = CompetitionTable(rows, {"Heavy Lift: not today"});
  EXPECT_NE(table.find("incomplete: an event above has no score"), std::string::npos) << table;
}

TEST(Reports, MissionListsFrontiersOnlyWhenItExplored) {
  mission::MissionReport r;
  r.task = mission::TaskKind::kExplore;
  r.status = {msgs::MissionState::kIncomplete, "2 frontiers left"};
  r.frontiers_left.push_back({1.25, -0.5, 12, true, true, false});
  const Json j = MissionJson(r, false, true);
  EXPECT_EQ(j["state"], "incomplete");
  ASSERT_EQ(j["frontiers_left"].size(), 1u);
  EXPECT_EQ(j["frontiers_left"][0]["given_up"], "for a while");
  EXPECT_FALSE(MissionJson(r, false, false).contains("frontiers_left"));
}

}  // namespace
}  // namespace mbot::reports
