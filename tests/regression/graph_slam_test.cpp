// Graph SLAM on the raw Intel Research Lab log, scored on the Kuemmerle et al. relations through
// the shipped config/graph_slam.ini: its first 15,000 events (about ten minutes, the default run,
// solved in line so the figures repeat) and, under its own label, the whole log
// (ctest --test-dir build -C graph_slam -L graph_slam).
#include <gtest/gtest.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <mrpt/graphs/CNetworkOfPoses.h>
#include <mrpt/graphslam/levmarq.h>

#include "mbot/msgs/source.hpp"
#include "run_config.hpp"
#include "mbot/mapping/pose_graph_io.hpp"

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
  ::testing::Test::RecordProperty("relations_scored", std::to_string(scored));
  ::testing::Test::RecordProperty("translation_m", std::to_string(trans));
  ::testing::Test::RecordProperty("rotation_deg", std::to_string(rot));
  // Every relation inside the span replayed is scored (one without a pose would be an error).
  EXPECT_GE(scored, 500);
  EXPECT_LE(trans, kMaxTranslationM);
  EXPECT_LE(rot, kMaxRotationDeg);
  EXPECT_LE(Get(j, {"relations", "max_translation_m"}), 0.25);
  EXPECT_GT(Get(j, {"graph", "loop_closures"}), 100);
  EXPECT_EQ(Get(j, {"graph", "sparse_scans"}), 0);
}

// What a user of a graph back end expects after a run: the pose graph as g2o (read here by MRPT,
// an independent reader, and solved by its Levenberg–Marquardt as by our solve of the file) and
// the map as PGM + YAML at a resolution other than the SLAM's.
TEST(GraphSlamRegression, WritesTheGraphAsG2oAndTheMapAtAnyResolution) {
  const std::string j = RunConfig(
      "graph_slam.ini", "graph_slam_g2o",
      {"pipeline.max_events=3000", "slam.graph_background=false", "slam.map_resolution_m=0.025"}, "metrics.json");
  ASSERT_FALSE(j.empty());
  const std::string dir = ::testing::TempDir() + "/graph_slam_g2o/";
  mrpt::graphs::CNetworkOfPoses2DInf g;
  g.loadFromTextFile(dir + "slam_graph.g2o");
  const double nodes = Get(j, {"graph", "nodes"}), submaps = Get(j, {"graph", "submaps"});
  ASSERT_GT(nodes, 100);
  EXPECT_EQ(g.nodes.size(), static_cast<size_t>(nodes + submaps));
  EXPECT_GT(g.edges.size(), 2 * g.nodes.size());
  // Solved again without the loop closures' Huber loss (not part of the format), by MRPT's sparse
  // Levenberg–Marquardt and by our generic g2o solve of the file read back: the same poses.
  g.root = 0;
  mrpt::graphslam::TResultInfoSpaLevMarq info;
  mrpt::graphslam::optimize_graph_spa_levmarq(g, info);
  mapping::G2oGraph ours = mapping::ReadG2o(dir + "slam_graph.g2o");
  EXPECT_EQ(ours.submaps, static_cast<int>(submaps));
  mapping::OptimizeG2o(&ours, mapping::PoseGraphOptions{1e9, 200, 1});
  double worst = 0;
  for (const mapping::G2oVertex& v : ours.vertices) {
    const mrpt::poses::CPose2D& p = g.nodes.at(v.id);
    worst = std::max(worst, std::hypot(v.pose.x - p.x(), v.pose.y - p.y()));
  }
  ::testing::Test::RecordProperty("mrpt_vs_ours_max_m", std::to_string(worst));
  EXPECT_LT(worst, 0.005);  // 0.76 mm measured

  std::ifstream yaml(dir + "slam_map.yaml");
  std::stringstream y;
  y << yaml.rdbuf();
  EXPECT_NE(y.str().find("resolution: 0.025"), std::string::npos) << y.str();
  EXPECT_NEAR(Get(j, {"map", "resolution"}), 0.025, 1e-12);
  // A 2.5 cm map of the same building: twice the cells a side of the 5 cm one, give or take a block.
  EXPECT_GT(Get(j, {"map", "width"}), 800);
}

// A session that starts on a finished map: the first 8,000 events of Intel map the building; a
// second run starts 5,000 events into the log with no pose (initial_pose = global), finds its first
// scan on that map by a whole-map search and tracks on. Both runs' poses agree at the same stamps.
// A map of another place is an error naming the map.
TEST(GraphSlamRegression, AResumedSessionFindsItselfOnAFinishedMap) {
  ASSERT_FALSE(RunConfig("graph_slam.ini", "graph_slam_map_first",
                         {"pipeline.max_events=8000", "slam.graph_background=false"}, "metrics.json")
                   .empty());
  const std::string map = ::testing::TempDir() + "/graph_slam_map_first/slam_map.yaml";
  ASSERT_FALSE(RunConfig("graph_slam.ini", "graph_slam_map_global",
                         {"pipeline.skip_events=5000", "pipeline.max_events=1500", "slam.graph_background=false",
                          "slam.initial_pose=global", "slam.map_file=" + map, "--unset slam.relations"},
                         "metrics.json")
                   .empty());
  const auto first = TumXy(::testing::TempDir() + "/graph_slam_map_first/slam.tum");
  const auto second = TumXy(::testing::TempDir() + "/graph_slam_map_global/slam.tum");
  ASSERT_GT(second.size(), 200u);
  const auto& [t0, p0] = *second.begin();
  ASSERT_TRUE(first.count(t0)) << t0;
  EXPECT_LT(std::hypot(p0.first - first.at(t0).first, p0.second - first.at(t0).second), 0.05);  // 1 cm measured
  double worst = 0;
  int both = 0;
  for (const auto& [t, p] : second) {
    if (!first.count(t)) continue;
    ++both;
    worst = std::max(worst, std::hypot(p.first - first.at(t).first, p.second - first.at(t).second));
  }
  EXPECT_GT(both, 200);
  EXPECT_LT(worst, 0.15);
  ::testing::Test::RecordProperty("worst_against_first_run_m", std::to_string(worst));

  try {
    RunConfig("graph_slam.ini", "graph_slam_map_wrong",
              {"pipeline.skip_events=5000", "pipeline.max_events=200", "slam.graph_background=false",
               "slam.initial_pose=global", "slam.map_file=" + Data("botlab/astar/empty.map"), "--unset slam.relations"},
              "metrics.json");
    FAIL() << "no error";
  } catch (const std::exception& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("whole-map search found no pose"), std::string::npos) << what;
    EXPECT_NE(what.find("empty.map"), std::string::npos) << what;
  }
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

// The scans of a log in the order the source gives them: each one's own stamp, and how many events
// came before it (`extra`: more [source] keys).
struct Scans {
  std::vector<int64_t> stamps;
  std::vector<long long> events_before;
};
Scans ReadScans(const std::string& path, const std::string& extra = "") {
  auto c = config::Config::FromString("[source]\ntype = auto\npath = " + path + "\n" + extra);
  config::Section s = c.GetSection("source");
  auto source = msgs::OpenSource(msgs::ParseSourceOptions(s));
  Scans scans;
  long long n = 0;
  while (auto ev = source->Next()) {
    if (ev->kind == msgs::EventKind::kLidar) scans.stamps.push_back(ev->stamp_us), scans.events_before.push_back(n);
    ++n;
  }
  return scans;
}

// The relations with each stamp moved to the same scan's stamp in the other log (the scans paired
// in order), written to `out`.
void MapRelations(const std::string& relations, const std::vector<int64_t>& from, const std::vector<int64_t>& to,
                  const std::string& out) {
  std::map<int64_t, int64_t> to_of;
  for (size_t i = 0; i < from.size(); ++i) to_of.emplace(from[i], to[i]);
  std::ifstream in(relations);
  std::ofstream o(out);
  std::string line;
  auto moved = [&](double t) {
    const auto it = to_of.find(static_cast<int64_t>(std::llround(t * 1e6)));
    if (it == to_of.end()) ADD_FAILURE() << "relation stamp " << t << " is no scan of the CARMEN log";
    return it == to_of.end() ? t : it->second * 1e-6;
  };
  while (std::getline(in, line)) {
    std::istringstream f(line);
    double t1, t2;
    if (!(f >> t1 >> t2)) continue;
    std::string rest;
    std::getline(f, rest);
    char head[64];
    std::snprintf(head, sizeof head, "%.6f %.6f", moved(t1), moved(t2));
    o << head << rest << "\n";
  }
}

// The Intel log as ROS 1 bags made by another project, through the same graph_slam.ini as the
// CARMEN log, unchanged (`--set source.path=<bag>`):
// intel.orig.bag keeps the log's stamps (its scans in time order, every ODOM line as /odom, the
// relations as they are); intel.clf2bag.bag restamps the scans and their odometry 0.1 s apart (the
// relations moved to the same scans' new stamps). Over the same scans (the first `clf_events` events
// of the CARMEN log; 0: all of it) every relation is scored; clf2bag scores as the CARMEN log does
// (within 2 mm and 0.05°), orig within the benchmark's bounds (below: its odometry differs).
void ExpectBagsScoreAsTheClf(long long clf_events, const std::string& tag) {
  std::vector<std::string> clf_sets = {"slam.graph_background=false"};
  if (clf_events > 0) clf_sets.push_back("pipeline.max_events=" + std::to_string(clf_events));
  const std::string clf = RunConfig("graph_slam.ini", "graph_slam_clf_" + tag, clf_sets, "metrics.json");
  ASSERT_FALSE(clf.empty());
  const double clf_trans = Get(clf, {"relations", "translation_m", "mean"});
  const double clf_rot = Get(clf, {"relations", "rotation_deg", "mean"});
  const double clf_scored = Get(clf, {"relations", "scored"});
  ::testing::Test::RecordProperty("clf_translation_m", std::to_string(clf_trans));
  ::testing::Test::RecordProperty("clf_rotation_deg", std::to_string(clf_rot));
  const Scans clf_scans = ReadScans(Data("carmen/intel-raw.clf.gz"));
  size_t replayed = clf_scans.stamps.size();  // scans within the CARMEN run's events
  if (clf_events > 0) {
    replayed = 0;
    while (replayed < clf_scans.stamps.size() && clf_scans.events_before[replayed] < clf_events) ++replayed;
  }
  for (const char* bag : {"intel.orig.bag", "intel.clf2bag.bag"}) {
    SCOPED_TRACE(bag);
    const std::string path = Data(std::string("carmen/") + bag);
    const Scans scans = ReadScans(path);
    ASSERT_EQ(scans.stamps.size(), clf_scans.stamps.size());
    std::string relations = Data("carmen/intel.relations");
    size_t last = replayed;  // the bag's events up to the same scans
    if (std::string(bag) == "intel.clf2bag.bag") {
      relations = ::testing::TempDir() + "/" + bag + ".relations";
      MapRelations(Data("carmen/intel.relations"), clf_scans.stamps, scans.stamps, relations);
    } else {
      // Its odometry has gaps of up to 3.1 s in the last quarter of the log (the config's
      // max_pose_gap_s = 4 spans them; the CARMEN log has each scan's own odometry).
      // In time order: up to the latest of the CARMEN run's scans.
      int64_t latest = INT64_MIN;
      for (size_t i = 0; i < replayed; ++i) latest = std::max(latest, clf_scans.stamps[i]);
      last = 0;
      while (last < scans.stamps.size() && scans.stamps[last] <= latest) ++last;
    }
    std::vector<std::string> sets = {"source.path=" + path, "slam.relations=" + relations,
                                     "slam.graph_background=false"};
    if (clf_events > 0 && last < scans.stamps.size())
      sets.push_back("pipeline.max_events=" + std::to_string(scans.events_before[last]));
    const std::string j =
        RunConfig("graph_slam.ini", std::string("graph_slam_") + bag + "_" + tag, sets, "metrics.json");
    ASSERT_FALSE(j.empty());
    const double trans = Get(j, {"relations", "translation_m", "mean"});
    const double rot = Get(j, {"relations", "rotation_deg", "mean"});
    ::testing::Test::RecordProperty(std::string(bag) + "_translation_m", std::to_string(trans));
    ::testing::Test::RecordProperty(std::string(bag) + "_rotation_deg", std::to_string(rot));
    ::testing::Test::RecordProperty(std::string(bag) + "_scored", std::to_string(Get(j, {"relations", "scored"})));
    EXPECT_EQ(Get(j, {"relations", "scored"}), clf_scored);
    if (std::string(bag) == "intel.clf2bag.bag") {  // the CARMEN log's scans and odometry, restamped
      EXPECT_NEAR(trans, clf_trans, 0.002);
      EXPECT_NEAR(rot, clf_rot, 0.05);
    } else {
      // Its /odom merges the log's ODOM lines (arrival stamps, in bursts) with the scans' own
      // odometry under other stamps: 1,249 of the first 3,001 scans have no odometry within 1 ms,
      // so the odometry at a scan is interpolated where the CARMEN run reads the FLASER line's own,
      // and its last quarter has gaps of up to 3.1 s and jumps the continuity check zeroes. Where
      // the odometry crossed a gap over graph_recover_gap_s (1 s) or a restart, the front end
      // searches the recovery window: the whole log then scores within 3 mm and 0.06° of the CARMEN
      // run (0.0346 m and 0.358° before, 2026-12-03).
      EXPECT_LE(trans, kMaxTranslationM);
      EXPECT_LE(rot, kMaxRotationDeg);
      if (clf_events == 0) {
        EXPECT_NEAR(trans, clf_trans, 0.003);
        EXPECT_NEAR(rot, clf_rot, 0.06);
      }
    }
  }
}

TEST(GraphSlamRegression, IntelRos1BagsScoreAsTheCarmenLogFirstTenMinutes) { ExpectBagsScoreAsTheClf(15000, "start"); }

TEST(GraphSlamFull, IntelEveryRelationWithinTheBenchmarkBounds) {
  const std::string j = RunConfig("graph_slam.ini", "graph_slam_intel_full", {}, "metrics.json");
  ASSERT_FALSE(j.empty());
  const double trans = Get(j, {"relations", "translation_m", "mean"});
  const double rot = Get(j, {"relations", "rotation_deg", "mean"});
  ::testing::Test::RecordProperty("translation_m", std::to_string(trans));
  ::testing::Test::RecordProperty("rotation_deg", std::to_string(rot));
  EXPECT_EQ(Get(j, {"relations", "scored"}), 2984);
  EXPECT_LE(trans, kMaxTranslationM);
  EXPECT_LE(rot, kMaxRotationDeg);
}

TEST(GraphSlamFull, IntelRos1BagsScoreAsTheCarmenLog) { ExpectBagsScoreAsTheClf(0, "full"); }

// ACES (Beeson's building, 180° laser to 50 m), the second building of the benchmark, through the
// same config/graph_slam.ini with only the log and its relations changed. Cartographer's published
// figures on it (Hess et al. 2016, Table II): 0.0375 m and 0.373°.
constexpr double kCartographerAcesM = 0.0375, kCartographerAcesDeg = 0.373;
std::vector<std::string> AcesSets(std::vector<std::string> more = {}) {
  std::vector<std::string> sets = {"source.path=" + Data("carmen/aces-raw.clf.gz"),
                                   "slam.relations=" + Data("carmen/aces.relations")};
  sets.insert(sets.end(), more.begin(), more.end());
  return sets;
}

TEST(GraphSlamRegression, AcesFirstFiveMinutesBelowCartographer) {
  const std::string j =
      RunConfig("graph_slam.ini", "graph_slam_aces_start",
                AcesSets({"pipeline.max_events=6000", "slam.graph_background=false"}), "metrics.json");
  ASSERT_FALSE(j.empty());
  const double trans = Get(j, {"relations", "translation_m", "mean"});
  const double rot = Get(j, {"relations", "rotation_deg", "mean"});
  ::testing::Test::RecordProperty("relations_scored", std::to_string(Get(j, {"relations", "scored"})));
  ::testing::Test::RecordProperty("translation_m", std::to_string(trans));
  ::testing::Test::RecordProperty("rotation_deg", std::to_string(rot));
  EXPECT_GE(Get(j, {"relations", "scored"}), 200);
  EXPECT_LE(trans, kCartographerAcesM);
  EXPECT_LE(rot, kCartographerAcesDeg);
  EXPECT_GT(Get(j, {"graph", "loop_closures"}), 50);
}

// The Freiburg hospital's format: ROBOTLASER1 lines (laser geometry and range limit in the line, the
// robot's odometry pose beside the laser's) and no ODOM line. The first `lines` lines of ACES
// rewritten so: the unchanged config reads the odometry from the scan lines and scores as the
// FLASER log does.
// `laser`: where the laser sits on the robot (identity: at its centre). The line's laser pose is the
// log's pose; its robot pose is that pose with the mount taken off (robot = laser ∘ mount⁻¹), so the
// robot's odometry is what a robot carrying the laser there would have read.
std::string AcesAsRobotLaser(int lines, const msgs::Pose2D& laser = {}, const std::string& name = "aces_robotlaser") {
  // Each caller names its own file, and it appears whole (renamed into place): ctest runs the tests
  // that share this helper at the same time.
  const std::string out = ::testing::TempDir() + "/" + name + ".log";
  const std::string partial = out + ".partial";
  auto c = config::Config::FromString("[source]\ntype = auto\npath = " + Data("carmen/aces-raw.clf.gz") + "\n");
  config::Section s = c.GetSection("source");
  auto source = msgs::OpenSource(msgs::ParseSourceOptions(s));
  std::ofstream o(partial);
  o.precision(17);
  int written = 0;
  std::optional<msgs::LidarScan> scan;
  while (auto ev = source->Next()) {
    if (ev->kind == msgs::EventKind::kLidar) scan = std::get<msgs::LidarScan>(ev->payload);
    if (ev->channel != "FLASER.odom" || !scan) continue;
    const auto& p = std::get<msgs::Pose2D>(ev->payload);
    const msgs::Pose2D r = p.Compose(laser.Inverse());
    // As the reader places ACES's 180 FLASER beams (CARMEN's rule: 1° apart, centred).
    if (scan->ranges_m.size() != 180u) ADD_FAILURE() << "ACES scans have 180 beams";
    const double inc = M_PI / 180, start = -inc * 179 / 2;
    o << "ROBOTLASER1 0 " << start << " " << inc * 179 << " " << inc << " " << scan->max_range_m << " 0.01 0 "
      << scan->ranges_m.size();
    for (float r : scan->ranges_m) o << " " << r;
    const double t = ev->stamp_us * 1e-6;
    o << " 0 " << p.x << " " << p.y << " " << p.theta << " " << r.x << " " << r.y << " " << r.theta << " 0 0 0 0 0 "
      << std::fixed << t << " nohost " << t << std::defaultfloat << "\n";
    scan.reset();
    if (++written >= lines) break;
  }
  o.close();
  std::filesystem::rename(partial, out);
  return out;
}

TEST(GraphSlamRegression, RobotLaserLogsWithoutOdomLinesScoreAsTheirFlaserLog) {
  const int scans = 1500;
  const std::string log = AcesAsRobotLaser(scans);
  const std::string flaser = RunConfig(
      "graph_slam.ini", "graph_slam_aces_flaser",
      AcesSets({"pipeline.max_events=" + std::to_string(4 * scans), "slam.graph_background=false"}), "metrics.json");
  const std::string robot = RunConfig("graph_slam.ini", "graph_slam_aces_robotlaser",
                                      AcesSets({"source.path=" + log, "slam.graph_background=false"}), "metrics.json");
  ASSERT_FALSE(flaser.empty());
  ASSERT_FALSE(robot.empty());
  EXPECT_EQ(Get(robot, {"scans"}), scans);
  EXPECT_EQ(Get(robot, {"relations", "scored"}), Get(flaser, {"relations", "scored"}));
  EXPECT_NEAR(Get(robot, {"relations", "translation_m", "mean"}), Get(flaser, {"relations", "translation_m", "mean"}),
              5e-4);
  // Naming an odometry channel the log does not have fails the run, and says what the log has.
  try {
    RunConfig("graph_slam.ini", "graph_slam_aces_wrong_odometry",
              AcesSets({"source.path=" + log, "slam.odometry_channel=FLASER.odom"}), "metrics.json");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("no scan was processed"), std::string::npos) << what;
    EXPECT_NE(what.find("odometry_channel = FLASER.odom is not in the input, which has ROBOTLASER1.odom"),
              std::string::npos)
        << what;
  }
}

// The relations of `relations` (between laser poses) as relations between the poses of a robot that
// carries the laser at `laser`: robot_i⁻¹ robot_j = laser · (p_i⁻¹ p_j) · laser⁻¹.
std::string RelationsOfTheRobot(const std::string& relations, const msgs::Pose2D& laser, const std::string& out) {
  std::ifstream in(relations);
  std::ofstream o(out);
  o.precision(12);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream f(line);
    double t1, t2, x, y, z, roll, pitch, yaw;
    if (!(f >> t1 >> t2 >> x >> y >> z >> roll >> pitch >> yaw)) continue;
    const msgs::Pose2D r = laser.Compose(msgs::Pose2D{x, y, yaw}).Compose(laser.Inverse());
    char head[64];
    std::snprintf(head, sizeof head, "%.6f %.6f ", t1, t2);
    o << head << r.x << " " << r.y << " 0 0 0 " << r.theta << "\n";
  }
  return out;
}

// A laser away from the robot's centre, on real data (issue 31): ACES rewritten as if its laser sat
// 0.25 m ahead, 0.10 m to the right and turned 17° on the robot (the ROBOTLASER1 lines carry both
// poses, so the mount is read from the log). The robot's trajectory scores on the relations moved to
// the robot's frame as the centred log scores on its own, within what the map's place on the grid
// alone changes (2026-12-04, these 1,500 scans: centred 0.0368 m; the laser only turned 17°, which
// turns the whole map against the 5 cm grid and nothing else, 0.0394 m; only shifted 0.0403 m; both
// 0.0418 m); taking the mount as the centre gives 0.092 m.
TEST(GraphSlamRegression, ALaserAwayFromTheRobotsCentreScoresAsACentredOne) {
  const int scans = 1500;
  const std::string centred_log = AcesAsRobotLaser(scans, {}, "aces_robotlaser_centred");
  const std::string centred =
      RunConfig("graph_slam.ini", "graph_slam_aces_centred",
                AcesSets({"source.path=" + centred_log, "slam.graph_background=false"}), "metrics.json");
  ASSERT_FALSE(centred.empty());
  const double c = Get(centred, {"relations", "translation_m", "mean"});
  ::testing::Test::RecordProperty("centred_translation_m", std::to_string(c));
  // The laser turned only (the map turns against the grid, nothing else changes), and turned and
  // moved; the latter also with its mount ignored.
  struct Case {
    const char* name;
    msgs::Pose2D mount;
    bool ignore_mount;
  };
  double turned = NAN, offset = NAN, ignored = NAN;
  for (const Case& k : {Case{"turned", {0.0, 0.0, 0.3}, false}, Case{"offset", {0.25, -0.10, 0.3}, false},
                        Case{"ignored", {0.25, -0.10, 0.3}, true}}) {
    const std::string log = AcesAsRobotLaser(scans, k.mount, std::string("aces_robotlaser_") + k.name);
    const std::string relations = RelationsOfTheRobot(Data("carmen/aces.relations"), k.mount,
                                                      ::testing::TempDir() + "/aces_" + k.name + ".relations");
    std::vector<std::string> sets = {"source.path=" + log, "slam.relations=" + relations,
                                     "slam.graph_background=false"};
    if (k.ignore_mount) sets.push_back("slam.lidar_pose=0, 0, 0");
    const std::string j =
        RunConfig("graph_slam.ini", std::string("graph_slam_aces_") + k.name, AcesSets(sets), "metrics.json");
    ASSERT_FALSE(j.empty()) << k.name;
    EXPECT_EQ(Get(j, {"relations", "scored"}), Get(centred, {"relations", "scored"})) << k.name;
    const double t = Get(j, {"relations", "translation_m", "mean"});
    ::testing::Test::RecordProperty(std::string(k.name) + "_translation_m", std::to_string(t));
    ::testing::Test::RecordProperty(std::string(k.name) + "_rotation_deg",
                                    std::to_string(Get(j, {"relations", "rotation_deg", "mean"})));
    (k.ignore_mount ? ignored : k.mount.x == 0 ? turned : offset) = t;
  }
  EXPECT_NEAR(offset, c, 0.006);
  EXPECT_NEAR(turned, c, 0.006);
  EXPECT_GT(ignored, 2 * c);  // the mount matters: as the robot's centre, the scans are 17° off
}

TEST(GraphSlamFull, AcesEveryRelationBelowCartographer) {
  const std::string j = RunConfig("graph_slam.ini", "graph_slam_aces_full", AcesSets(), "metrics.json");
  ASSERT_FALSE(j.empty());
  const double trans = Get(j, {"relations", "translation_m", "mean"});
  const double rot = Get(j, {"relations", "rotation_deg", "mean"});
  ::testing::Test::RecordProperty("translation_m", std::to_string(trans));
  ::testing::Test::RecordProperty("rotation_deg", std::to_string(rot));
  EXPECT_EQ(Get(j, {"relations", "scored"}), 1279);
  EXPECT_LE(trans, kCartographerAcesM);
  EXPECT_LE(rot, kCartographerAcesDeg);
}

// Harder on purpose (issue 31): odometry noise (5 % of each step), a glitch every 30 s that jumps the
// odometry by up to 1 m and stays, every other scan dropped and the range capped at 8 m, on the
// first minutes of Intel and ACES. Scored on the relations whose both scans were kept. The front
// end's recovery search finds the motion where the odometry's prior does not fit; without it
// (graph_recover_below = 0) the same Intel slice scored 1.27 m (2026-12-03).
void ExpectHardSliceWithinBounds(const std::string& log, const std::string& relations, long long events,
                                 double max_trans_m, double max_rot_deg, const std::string& tag) {
  const Scans scans = ReadScans(Data(log));
  std::set<int64_t> kept;
  for (size_t i = 0; i < scans.stamps.size(); i += 2) kept.insert(scans.stamps[i]);
  const std::string kept_relations = ::testing::TempDir() + "/" + tag + "_kept.relations";
  {
    std::ifstream in(Data(relations));
    std::ofstream out(kept_relations);
    std::string line;
    while (std::getline(in, line)) {
      std::istringstream f(line);
      double t1, t2;
      if (f >> t1 >> t2 && kept.count(std::llround(t1 * 1e6)) && kept.count(std::llround(t2 * 1e6)))
        out << line << "\n";
    }
  }
  const std::vector<std::string> sets = {"source.path=" + Data(log),
                                         "slam.relations=" + kept_relations,
                                         "pipeline.max_events=" + std::to_string(events),
                                         "slam.graph_background=false",
                                         "slam.odometry_noise_trans=0.05",
                                         "slam.odometry_noise_rot=0.05",
                                         "slam.odometry_jump_every_s=30",
                                         "slam.odometry_jump_max_m=1",
                                         "slam.scan_every=2",
                                         "slam.max_range_m=8"};
  const std::string j = RunConfig("graph_slam.ini", "graph_slam_hard_" + tag, sets, "metrics.json");
  ASSERT_FALSE(j.empty());
  const double trans = Get(j, {"relations", "translation_m", "mean"});
  const double rot = Get(j, {"relations", "rotation_deg", "mean"});
  ::testing::Test::RecordProperty("translation_m", std::to_string(trans));
  ::testing::Test::RecordProperty("rotation_deg", std::to_string(rot));
  ::testing::Test::RecordProperty("recoveries", std::to_string(Get(j, {"graph", "recoveries"})));
  EXPECT_GE(Get(j, {"relations", "scored"}), 50);  // Intel's slice keeps 248, ACES's 67
  EXPECT_LE(trans, max_trans_m);
  EXPECT_LE(rot, max_rot_deg);
  EXPECT_LE(Get(j, {"relations", "max_translation_m"}), 0.5);
  EXPECT_GE(Get(j, {"graph", "recoveries"}), 1);
}

TEST(GraphSlamRegression, IntelMadeHarderStaysWithinBounds) {
  // Clean, the same kept scans scored 0.0165 m and 0.21° (2026-12-03); made harder, 0.0287 m and
  // 0.28° (2026-12-05), and 0.0200 m and 0.24° with the recovery bounded by the odometry's step and no
  // margin (16 recoveries).
  ExpectHardSliceWithinBounds("carmen/intel-raw.clf.gz", "carmen/intel.relations", 15000, 0.035, 0.5, "intel");
}

TEST(GraphSlamRegression, AcesMadeHarderStaysWithinBounds) {
  // Clean, the same kept scans scored 0.0335 m and 0.24° (2026-12-03); made harder, 0.0405 m and
  // 0.25° (2026-12-05).
  ExpectHardSliceWithinBounds("carmen/aces-raw.clf.gz", "carmen/aces.relations", 6000, 0.065, 0.5, "aces");
}

// Glass and people (issue 31): a fifth of the walls (1 m patches) are glass — half of the beams
// ending there give no return (the sensor's maximum), the others a return 1.5-3 times as far — and
// three people walk about the robot. A beam at the sensor's maximum is no return and clears nothing,
// and a recovery searches no farther than the odometry since the last matched scan plus
// graph_recover_slack_m (across an odometry gap, than the robot's top speed allows). Seed `seed` of
// `events` events of `log`: at least `min_glass` and `min_person` beams changed, and the relations'
// mean within `max_trans_m` and `max_rot_deg`, the largest within `max_largest_m`.
void ExpectGlassAndPeopleWithinBounds(const std::string& log, const std::string& relations, int events,
                                      const std::string& tag, double min_glass, double min_person, double max_trans_m,
                                      double max_rot_deg, double max_largest_m, int seed = 1) {
  const std::vector<std::string> sets = {"source.path=" + Data(log),
                                         "slam.relations=" + Data(relations),
                                         "pipeline.max_events=" + std::to_string(events),
                                         "pipeline.seed=" + std::to_string(seed),
                                         "slam.graph_background=false",
                                         "slam.scan_glass_share=0.2",
                                         "slam.scan_people=3"};
  const std::string j = RunConfig("graph_slam.ini", "graph_slam_glass_people_" + tag, sets, "metrics.json");
  ASSERT_FALSE(j.empty());
  const double trans = Get(j, {"relations", "translation_m", "mean"});
  ::testing::Test::RecordProperty("translation_m", std::to_string(trans));
  EXPECT_GT(Get(j, {"injected", "glass_beams"}), min_glass);
  EXPECT_GT(Get(j, {"injected", "person_beams"}), min_person);
  EXPECT_LE(trans, max_trans_m);
  EXPECT_LE(Get(j, {"relations", "rotation_deg", "mean"}), max_rot_deg);
  EXPECT_LE(Get(j, {"relations", "max_translation_m"}), max_largest_m);
}

// The first 10 minutes of Intel. Before, this slice scored 0.0928 m (largest 1.45 m); with the
// no-return rule and no bound 1.42 m (2026-12-05). Clean, the same events score 0.0172 m and
// 0.23 deg; with glass and people 0.0223 m and 0.28 deg. Seed 3 scores 0.0205 m.
TEST(GraphSlamRegression, IntelWithGlassAndPeopleStaysWithinBounds) {
  ExpectGlassAndPeopleWithinBounds("carmen/intel-raw.clf.gz", "carmen/intel.relations", 15000, "intel", 50000, 10000,
                                   0.03, 0.5, 0.3);
}

// Seed 2 hides much of one scan at t = 976053147.979, 1.27 s after the one before (the log's clock
// jumps there; the odometry shows the robot standing). The local fit scores 0.31 against a mean of
// 0.71, and a look-alike place 1.52 m away fitted better: searching the whole recovery window, the
// robot jumped there, 0.0235 m with a largest relation error of 1.84 m (2026-12-05). The window is a
// square (±1.5 m); a best find beyond its reach as a distance is now refused: 0.0187 m, largest
// 0.068 m, with or without the clock's bound on the gap (2 × 0.37 m/s × 1.27 s + 0.3 m = 1.24 m).
TEST(GraphSlamRegression, IntelWithGlassAndPeopleAcrossAClockGapStaysWithinBounds) {
  ExpectGlassAndPeopleWithinBounds("carmen/intel-raw.clf.gz", "carmen/intel.relations", 15000, "intel_seed2", 50000,
                                   10000, 0.025, 0.5, 0.3, 2);
}

// ACES's first 6,000 events. A scan partly hidden by people fits poorly where it is, and a look-alike
// place 1.6 m away fitted better (by more than the 0.15 margin of then): the robot jumped there on an
// odometry step of 8 cm and back on the next scan. A glitch is part of the odometry's own step, so
// the recovery bound keeps it out. Without the bound this slice scored 0.0600 m (largest 1.52 m), and
// 0.0592 m with the 0.15 margin of before; with it 0.0456 m (largest 0.37 m); clean 0.0370 m and
// 0.26 deg (2026-12-05). Seeds 2 and 3: 0.0415 and 0.0446 m (largest 0.21 and 0.24 m), against
// 0.0493 (1.32) and 0.0446 (0.24) before the bound, with the margin.
TEST(GraphSlamRegression, AcesWithGlassAndPeopleStaysWithinBounds) {
  ExpectGlassAndPeopleWithinBounds("carmen/aces-raw.clf.gz", "carmen/aces.relations", 6000, "aces", 20000, 5000, 0.05,
                                   0.5, 0.5);
}

}  // namespace
}  // namespace mbot::app
