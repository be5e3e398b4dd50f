// Graph SLAM on the raw Intel Research Lab log, scored on the Kuemmerle et al. relations through
// the shipped config/graph_slam.ini: its first 15,000 events (about ten minutes, the default run,
// solved in line so the figures repeat) and, under its own label, the whole log
// (ctest --test-dir build -C graph_slam -L graph_slam).
#include <gtest/gtest.h>

#include <stdexcept>

#include "run_config.hpp"

namespace mbot::app {
namespace {

std::string Data(const std::string& rel) { return config::DatasetsDir() + "/" + rel; }

// Graph Mapping's figures on these relations (Kuemmerle et al. 2009, as quoted by Hess et al.
// 2016): 0.031 m and 1.3°. The bound: at most 0.03 m and 1°.
constexpr double kMaxTranslationM = 0.03, kMaxRotationDeg = 1.0;

TEST(GraphSlamRegression, IntelFirstTenMinutesWithinTheBenchmarkBounds) {
  const std::string j = RunConfig("graph_slam.ini", "graph_slam_intel_start",
                                  {"pipeline.max_events=15000", "slam.graph_background=false"}, "metrics.json");
  ASSERT_FALSE(j.empty());
  const double scored = Get(j, {"relations", "scored"});
  const double trans = Get(j, {"relations", "translation_m", "mean"});
  const double rot = Get(j, {"relations", "rotation_deg", "mean"});
  RecordProperty("relations_scored", std::to_string(scored));
  RecordProperty("translation_m", std::to_string(trans));
  RecordProperty("rotation_deg", std::to_string(rot));
  // Every relation inside the span replayed is scored (one without a pose would be an error).
  EXPECT_GE(scored, 500);
  EXPECT_LE(trans, kMaxTranslationM);
  EXPECT_LE(rot, kMaxRotationDeg);
  EXPECT_LE(Get(j, {"relations", "max_translation_m"}), 0.25);
  EXPECT_GT(Get(j, {"graph", "loop_closures"}), 100);
  EXPECT_EQ(Get(j, {"graph", "sparse_scans"}), 0);
}

TEST(GraphSlamRegression, RelationsThatMatchNoScanAreAnErrorNamingTheFileAndStamp) {
  // FR079's relations use log-relative stamps (1215 s …): none falls within the Intel log.
  try {
    RunConfig(
        "graph_slam.ini", "graph_slam_wrong_relations",
        {"pipeline.max_events=3000", "slam.graph_background=false", "slam.relations=" + Data("carmen/fr079.relations")},
        "metrics.json");
    FAIL() << "no error";
  } catch (const std::exception& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("fr079.relations"), std::string::npos) << what;
    EXPECT_NE(what.find("1216.630413"), std::string::npos) << what;
  }
}

TEST(GraphSlamFull, IntelEveryRelationWithinTheBenchmarkBounds) {
  const std::string j = RunConfig("graph_slam.ini", "graph_slam_intel_full", {}, "metrics.json");
  ASSERT_FALSE(j.empty());
  const double trans = Get(j, {"relations", "translation_m", "mean"});
  const double rot = Get(j, {"relations", "rotation_deg", "mean"});
  RecordProperty("translation_m", std::to_string(trans));
  RecordProperty("rotation_deg", std::to_string(rot));
  EXPECT_EQ(Get(j, {"relations", "scored"}), 2984);
  EXPECT_LE(trans, kMaxTranslationM);
  EXPECT_LE(rot, kMaxRotationDeg);
}

}  // namespace
}  // namespace mbot::app
