// What is known about every shared dataset, asserted through the project's own readers.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/drivers/map_io.hpp"
#include "mbot/drivers/source_options.hpp"
#include "mbot/pipeline/pipeline.hpp"

namespace fs = std::filesystem;

namespace mbot::drivers {

using namespace msgs;  // the event vocabulary
namespace {

std::string Data(const std::string& rel) { return config::DatasetsDir() + "/" + rel; }

struct ChannelSummary {
  long long count = 0;
  int64_t first = 0, last = 0;
  size_t beams_min = SIZE_MAX, beams_max = 0;
  double range_max = 0, range_min = INFINITY;
  std::vector<double> spacing;
  EventKind kind = EventKind::kOther;
  double Rate() const { return (count - 1) / ((last - first) * 1e-6); }
  double MedianSpacingDeg() const {
    auto v = spacing;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2] * 180 / M_PI;
  }
};

struct Summary {
  std::map<std::string, ChannelSummary> channels;
  std::map<std::string, ChannelInfo> infos;
  SourceDiagnostics diagnostics;
  std::string format;
  long long backwards = 0;
  bool ground_truth = false;
  long long events = 0;
};

Summary Read(const std::string& path) {
  SourceOptions o;
  o.path = path;
  auto src = OpenSource(o);
  Summary s;
  int64_t last = INT64_MIN;
  while (auto ev = src->Next()) {
    ++s.events;
    if (ev->t_us < last) ++s.backwards;
    last = ev->t_us;
    auto& c = s.channels[ev->channel];
    if (c.count++ == 0) c.first = ev->t_us;
    c.last = ev->t_us;
    c.kind = ev->kind;
    s.ground_truth |= ev->kind == EventKind::kGroundTruth;
    if (auto* scan = std::get_if<LidarScan>(&ev->payload)) {
      c.beams_min = std::min(c.beams_min, scan->ranges_m.size());
      c.beams_max = std::max(c.beams_max, scan->ranges_m.size());
      for (float r : scan->ranges_m) {
        if (std::isfinite(r) && r > 0) {
          c.range_max = std::max<double>(c.range_max, r);
          c.range_min = std::min<double>(c.range_min, r);
        }
      }
      if (scan->angles_rad.size() > 2) {
        c.spacing.push_back(std::abs(msgs::WrapAngle(scan->angles_rad[2] - scan->angles_rad[1])));
      }
    }
  }
  s.infos = src->channels();
  s.diagnostics = src->diagnostics();
  s.format = src->Format();
  return s;
}

class QuietLogs : public ::testing::Environment {
  void SetUp() override { log::SetLevel(log::Level::kError); }
};
const auto* const kQuiet = ::testing::AddGlobalTestEnvironment(new QuietLogs);

void ExpectClean(const Summary& s) {
  EXPECT_EQ(s.backwards, 0) << "event time must be monotonic";
  EXPECT_EQ(s.diagnostics.rejected_messages, 0);
  EXPECT_EQ(s.diagnostics.resyncs, 0);
  EXPECT_FALSE(s.diagnostics.truncated_tail);
}

// ---- botlab LCM logs ------------------------------------------------------------------------

struct LegacyLog {
  const char* file;
  long long lidar, true_pose, odometry, encoders;
};

void PrintTo(const LegacyLog& l, std::ostream* os) { *os << l.file; }

class LegacyLogTest : public ::testing::TestWithParam<LegacyLog> {};

TEST_P(LegacyLogTest, ChannelsCountsRatesAndGroundTruth) {
  const auto& p = GetParam();
  const Summary s = Read(Data(std::string("botlab/legacy_2017/") + p.file));
  ExpectClean(s);
  EXPECT_EQ(s.format, "LCM log");
  EXPECT_TRUE(s.ground_truth);
  const auto& lidar = s.channels.at("LIDAR");
  EXPECT_EQ(lidar.count, p.lidar);
  EXPECT_NEAR(lidar.Rate(), 5.0, 0.2);
  EXPECT_GE(lidar.beams_min, 195u);
  EXPECT_LE(lidar.beams_max, 220u);
  EXPECT_GT(lidar.range_min, 0.0);
  EXPECT_LE(lidar.range_max, 40.0);  // Scanse Sweep limit
  EXPECT_EQ(s.channels.at("TRUE_POSE").count, p.true_pose);
  EXPECT_GT(s.channels.at("TRUE_POSE").Rate(), 85.0);  // OptiTrack, ~96 Hz nominal
  EXPECT_LT(s.channels.at("TRUE_POSE").Rate(), 100.0);
  EXPECT_EQ(s.channels.at("ODOMETRY").count, p.odometry);
  EXPECT_NEAR(s.channels.at("ODOMETRY").Rate(), 50.0, 2.0);
  EXPECT_EQ(s.channels.at("MBOT_ENCODERS").count, p.encoders);
  EXPECT_EQ(s.channels.at("MBOT_ENCODERS").kind, EventKind::kEncoders);
  EXPECT_EQ(s.channels.at("MBOT_IMU").kind, EventKind::kImu);
  EXPECT_EQ(s.channels.at("SLAM_POSE").kind, EventKind::kReferencePose);
  EXPECT_EQ(s.channels.at("SLAM_MAP").kind, EventKind::kMap);
  EXPECT_NE(s.infos.at("MBOT_ENCODERS").generation.find("legacy"), std::string::npos);
  EXPECT_EQ(s.diagnostics.unknown_messages, 0);
}

INSTANTIATE_TEST_SUITE_P(Botlab, LegacyLogTest,
                         ::testing::Values(LegacyLog{"sweep_drive_square_10mx10m_5cm.log", 125, 2428, 1240, 620},
                                           LegacyLog{"sweep_convex_10mx10m_5cm.log", 133, 2543, 1324, 662},
                                           LegacyLog{"sweep_convex_10mx10m_5cm_offcenter.log", 107, 1871, 1060, 530}),
                         [](const ::testing::TestParamInfo<LegacyLog>& i) {
                           std::string n = i.param.file;
                           n = n.substr(0, n.find('.'));
                           for (char& ch : n) ch = std::isalnum(static_cast<unsigned char>(ch)) ? ch : '_';
                           return n;
                         });

TEST(BotlabLogs, DriveSquareGroundTruthTravelsAboutFourMetres) {
  SourceOptions o;
  o.path = Data("botlab/legacy_2017/sweep_drive_square_10mx10m_5cm.log");
  auto src = OpenSource(o);
  double path = 0;
  msgs::Pose2D last;
  bool first = true;
  while (auto ev = src->Next()) {
    if (ev->kind != EventKind::kGroundTruth) continue;
    const auto p = std::get<msgs::Pose2D>(ev->payload);
    if (!first) path += std::hypot(p.x - last.x, p.y - last.y);
    last = p;
    first = false;
  }
  EXPECT_NEAR(path, 4.3, 0.2);  // provenance: 4.3 m GT path
}

TEST(BotlabLogs, MaebotConvexUsesMaebotTypesAndIsReorderedToMonotonicTime) {
  const Summary s = Read(Data("botlab/legacy_2017/maebot_convex.log"));
  ExpectClean(s);  // the file has records up to 2.8 ms out of order; the source re-sorts them
  EXPECT_TRUE(s.ground_truth);
  EXPECT_EQ(s.channels.at("RPLIDAR_LASER").count, 493);
  EXPECT_EQ(s.channels.at("RPLIDAR_LASER").kind, EventKind::kLidar);
  EXPECT_EQ(s.channels.at("TRUE_POSE").count, 2103);
  EXPECT_EQ(s.channels.at("MAEBOT_ENCODERS").count, 3680);
  EXPECT_EQ(s.channels.at("MAEBOT_IMU").kind, EventKind::kImu);
  EXPECT_EQ(s.infos.at("MAEBOT_ENCODERS").generation, "Maebot");
  EXPECT_LE(s.channels.at("RPLIDAR_LASER").range_max, 8.0);  // RPLidar A1 range
}

TEST(BotlabLogs, ModernF23LogDecodesCurrentTypes) {
  const Summary s = Read(Data("botlab/modern_small_logs/f23_lcmlog-2023-11-07.00"));
  ExpectClean(s);
  EXPECT_EQ(s.diagnostics.unknown_messages, 0);
  EXPECT_EQ(s.channels.at("MBOT_ENCODERS").count, 243);
  EXPECT_EQ(s.infos.at("MBOT_ENCODERS").generation, "2023+");
  EXPECT_EQ(s.infos.at("MBOT_IMU").generation, "2023+");
  EXPECT_EQ(s.channels.at("MBOT_ODOMETRY").kind, EventKind::kOdometry);
  EXPECT_EQ(s.channels.at("MBOT_VEL_CMD").kind, EventKind::kMotorCommand);
  EXPECT_EQ(s.channels.at("MBOT_MOTOR_PWM").kind, EventKind::kMotorCommand);
  EXPECT_NEAR(s.channels.at("MBOT_ENCODERS").Rate(), 24.6, 1.0);
  EXPECT_FALSE(s.ground_truth);
}

TEST(BotlabLogs, W22AndW25Logs) {
  const Summary w22 = Read(Data("botlab/modern_small_logs/w22_lcmlog-2022-02-14.04"));
  ExpectClean(w22);
  EXPECT_EQ(w22.channels.at("ODOMETRY").count, 738);
  EXPECT_NEAR(w22.channels.at("ODOMETRY").Rate(), 100.0, 3.0);  // 738 messages over their own 7.4 s
  EXPECT_NE(w22.infos.at("MBOT_IMU").generation.find("legacy"), std::string::npos);
  const Summary w25 = Read(Data("botlab/modern_small_logs/w25_mbot_square_log.log"));
  ExpectClean(w25);
  EXPECT_EQ(w25.channels.at("MBOT_ODOMETRY").count, 1854);
  EXPECT_NEAR(w25.channels.at("MBOT_ODOMETRY").Rate(), 24.3, 1.0);
}

// ---- MRPT rawlogs -----------------------------------------------------------------------------

TEST(MrptRawlogs, LocalizationDemoHas37SensoryFrames) {
  SourceOptions o;
  o.path = Data("mrpt/localization_demo.rawlog");
  auto src = OpenSource(o);
  std::map<std::string, std::string> details;
  long long scans = 0, backwards = 0;
  int64_t last = INT64_MIN;
  while (auto ev = src->Next()) {
    scans += ev->kind == EventKind::kLidar;
    backwards += ev->t_us < last;
    last = ev->t_us;
  }
  for (const auto& [k, v] : src->Details()) details[k] = v;
  EXPECT_EQ(details.at("sensory frames"), "37");
  EXPECT_EQ(details.at("actions"), "37");
  EXPECT_EQ(scans, 37);
  EXPECT_EQ(backwards, 0);
  EXPECT_EQ(src->Format(), "MRPT rawlog (actions / sensory frames)");
}

TEST(MrptRawlogs, TelecomFacultyLoop) {
  const Summary s = Read(Data("mrpt/2006-01ENE-21-SENA_Telecom Faculty_one_loop_only.rawlog"));
  ExpectClean(s);
  long long scans = 0;
  for (const auto& [name, c] : s.channels) {
    if (c.kind == EventKind::kLidar) {
      scans += c.count;
      EXPECT_EQ(c.beams_min, 361u);
      EXPECT_NEAR(c.MedianSpacingDeg(), 0.5, 1e-3);
      EXPECT_LE(c.range_max, 81.0);
    }
  }
  EXPECT_EQ(scans, 225);
  EXPECT_EQ(s.channels.at("ACTION_ODOMETRY").count, 224);
}

// ---- CARMEN logs ------------------------------------------------------------------------------

struct CarmenLog {
  const char* file;
  long long scans;
  size_t beams;
  double spacing_deg;
  long long odom;
};

void PrintTo(const CarmenLog& l, std::ostream* os) { *os << l.file; }

class CarmenLogTest : public ::testing::TestWithParam<CarmenLog> {};

TEST_P(CarmenLogTest, ScansBeamsSpacingAndOdometry) {
  const auto& p = GetParam();
  const Summary s = Read(Data(std::string("carmen/") + p.file));
  EXPECT_EQ(s.backwards, 0);
  EXPECT_EQ(s.diagnostics.rejected_messages, 0);
  const auto& laser = s.channels.at("FLASER");
  EXPECT_EQ(laser.count, p.scans);
  EXPECT_EQ(laser.beams_min, p.beams);
  EXPECT_EQ(laser.beams_max, p.beams);
  EXPECT_NEAR(laser.MedianSpacingDeg(), p.spacing_deg, 1e-3);
  EXPECT_LE(laser.range_max, 81.92);
  EXPECT_EQ(s.channels.at("ODOM").count, p.odom);
  EXPECT_EQ(s.channels.at("FLASER.pose").kind, EventKind::kReferencePose);
  EXPECT_EQ(s.channels.at("FLASER.odom").kind, EventKind::kOdometry);
  EXPECT_FALSE(s.ground_truth);  // corrected poses are a reference, not ground truth
}

INSTANTIATE_TEST_SUITE_P(Carmen, CarmenLogTest,
                         ::testing::Values(CarmenLog{"intel-corrected.log.gz", 910, 180, 1.0, 14541},
                                           CarmenLog{"aces-corrected.log.gz", 440, 180, 1.0, 7814},
                                           CarmenLog{"freiburg-079-corrected.log.gz", 4791, 360, 0.5, 9725},
                                           CarmenLog{"csail-corrected.log.gz", 406, 361, 0.5, 2394}),
                         [](const ::testing::TestParamInfo<CarmenLog>& i) {
                           std::string n = i.param.file;
                           n = n.substr(0, n.find('-', n.find('-') + 1) == std::string::npos ? n.find('-')
                                                                                             : n.find("-corrected"));
                           for (char& ch : n) ch = std::isalnum(static_cast<unsigned char>(ch)) ? ch : '_';
                           return n;
                         });

TEST(CarmenLogs, IntelSpansAbout2650Seconds) {
  const Summary s = Read(Data("carmen/intel-corrected.log.gz"));
  const auto& laser = s.channels.at("FLASER");
  EXPECT_NEAR((laser.last - laser.first) * 1e-6, 2650.9, 50.0);
}

// ---- maps -------------------------------------------------------------------------------------

TEST(Maps, BotlabLegacyMapsAre200By200At5cm) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(Data("botlab/legacy_2017/maps"))) {
    SCOPED_TRACE(e.path().string());
    const auto g = ReadBotlabMap(e.path().string());
    EXPECT_EQ(g.width(), 200);
    EXPECT_EQ(g.height(), 200);
    EXPECT_DOUBLE_EQ(g.resolution(), 0.05);
    EXPECT_DOUBLE_EQ(g.origin_x(), -5.0);
    EXPECT_GT(g.CountCells().occupied, 100);
    ++n;
  }
  EXPECT_EQ(n, 7);
}

TEST(Maps, ArenaMapsAre800By800At25mmAndRoundTrip) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(Data("botlab/mbot_example_logs_maps"))) {
    SCOPED_TRACE(e.path().string());
    const auto g = ReadBotlabMap(e.path().string());
    EXPECT_EQ(g.width(), 800);
    EXPECT_DOUBLE_EQ(g.resolution(), 0.025);
    EXPECT_DOUBLE_EQ(g.origin_x(), -10.0);
    const std::string tmp = (fs::temp_directory_path() / "mbot_regression_roundtrip.map").string();
    WriteBotlabMap(g, tmp);
    EXPECT_EQ(ReadBotlabMap(tmp), g);
    const std::string yaml = (fs::temp_directory_path() / "mbot_regression_roundtrip.yaml").string();
    WriteRosMap(g, yaml);
    EXPECT_EQ(ReadRosMap(yaml), g);
    ++n;
  }
  EXPECT_EQ(n, 4);
}

TEST(Maps, AstarMapsAndCases) {
  const std::map<std::string, std::pair<int, int>> expect = {
      {"empty", {300, 300}}, {"filled", {300, 300}}, {"narrow", {300, 300}}, {"wide", {300, 300}}};
  for (const char* name : {"convex", "empty", "filled", "maze", "narrow", "wide"}) {
    SCOPED_TRACE(name);
    const auto g = ReadBotlabMap(Data(std::string("botlab/astar/") + name + ".map"));
    EXPECT_GT(g.width(), 0);
    if (auto it = expect.find(name); it != expect.end()) {
      EXPECT_EQ(g.width(), it->second.first);
      EXPECT_EQ(g.height(), it->second.second);
    }
    const auto cells = g.CountCells();
    if (std::string(name) == "filled") {
      EXPECT_EQ(cells.occupied, g.width() * g.height());
    }
    if (std::string(name) == "empty") {
      EXPECT_EQ(cells.free, g.width() * g.height());
    }
  }
}

TEST(Maps, RosWorlds) {
  for (const char* name : {"depot", "warehouse", "willow-full", "100by100_20"}) {
    SCOPED_TRACE(name);
    const auto g = ReadRosMap(Data(std::string("worlds/") + name + ".yaml"));
    const auto c = g.CountCells();
    EXPECT_GT(c.occupied, 0);
    EXPECT_GT(c.free, c.occupied);  // negate is honoured: mostly free space
  }
}

TEST(Maps, MovingAiMapsMatchTheirHeaders) {
  int n = 0;
  for (const auto& e : fs::recursive_directory_iterator(Data("movingai/maps"))) {
    if (e.path().extension() != ".map") continue;
    SCOPED_TRACE(e.path().string());
    const auto g = ReadAnyMap(e.path().string());
    EXPECT_GT(g.CountCells().free, 0);
    ++n;
  }
  EXPECT_EQ(n, 19);
}

TEST(Maps, MrptGridmap) {
  const auto g = ReadMrptGridmap(Data("mrpt/2006-MalagaCampus.gridmap.gz"));
  EXPECT_EQ(g.width(), 1888);
  EXPECT_EQ(g.height(), 2738);
  EXPECT_NEAR(g.resolution(), 0.08, 1e-6);
  EXPECT_GT(g.CountCells().occupied, 1000);
}

// ---- the application end to end ---------------------------------------------------------------

// Runs the shipped replay configuration into a fresh folder `out`; `stop` set = Ctrl-C at once.
pipeline::RunSummary RunReplay(const std::string& out, bool stop_at_once) {
  auto c = config::Config::Load(std::string(MBOT_SOURCE_DIR) + "/config/replay.ini");
  fs::remove_all(out);
  c.Set("output.dir=" + out);
  c.Set("pipeline.progress=off");
  c.Set("inspect.print=false");
  auto plan = pipeline::BuildPlan(c);
  std::atomic<bool> stop{stop_at_once};
  return pipeline::RunPlan(plan, stop);
}

TEST(App, InspectPipelineOnARealLogWritesItsSummary) {
  const std::string out = (fs::temp_directory_path() / "mbot_regression_replay").string();
  const auto summary = RunReplay(out, false);
  EXPECT_EQ(summary.events, 6702);  // every record (6703) but lcm-logger's self test
  for (const char* f : {"inspect.json", "odometry.tum", "ground_truth.tum", "staff_slam.tum", "staff_slam_map.map",
                        "staff_slam_map.yaml", "staff_slam_map.pgm", "staff_slam_map.png"}) {
    EXPECT_TRUE(fs::exists(out + "/" + f)) << f;
  }
  std::ifstream gt(out + "/ground_truth.tum");
  std::string line;
  int lines = 0;
  while (std::getline(gt, line)) lines += line[0] != '#';
  EXPECT_EQ(lines, 2428);
  const auto map = ReadBotlabMap(out + "/staff_slam_map.map");
  EXPECT_EQ(map.width(), 200);
}

TEST(App, InterruptedRunStillWritesOutputs) {
  const std::string out = (fs::temp_directory_path() / "mbot_regression_interrupted").string();
  const auto summary = RunReplay(out, true);  // as if Ctrl-C came before the first event
  EXPECT_TRUE(summary.interrupted);
  std::ifstream in(out + "/inspect.json");
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_NE(ss.str().find("\"interrupted\": true"), std::string::npos);
}

}  // namespace
}  // namespace mbot::drivers
