#include <gtest/gtest.h>

#include <cmath>

#include "mbot/lcm/lcm_log.hpp"
#include "mbot/lcm/lcm_sources.hpp"
#include "mbot_lcm_msgs/mbot_encoders_t.hpp"
#include "mbot_lcm_msgs/twist2D_t.hpp"
#include "mbot_legacy/lidar_t.hpp"
#include "mbot_legacy/occupancy_grid_t.hpp"
#include "mbot_legacy/pose_xyt_t.hpp"
#include "test_util.hpp"

namespace mbot::lcmio {

using namespace msgs;  // the event vocabulary
namespace {

mbot_legacy::lidar_t Scan(int n) {
  mbot_legacy::lidar_t m;
  m.utime = 5;
  m.num_ranges = n;
  for (int i = 0; i < n; ++i) {
    m.ranges.push_back(1.0f + i);
    m.thetas.push_back(0.1f * i);
    m.times.push_back(1000 + i);
    m.intensities.push_back(0);
  }
  return m;
}

mbot_legacy::pose_xyt_t Pose(float x, float y, float t) {
  mbot_legacy::pose_xyt_t p;
  p.utime = 0;
  p.x = x;
  p.y = y;
  p.theta = t;
  return p;
}

std::vector<Event> ReadAll(const std::string& path, SourceDiagnostics* diag = nullptr) {
  SourceOptions o;
  o.path = path;
  auto src = OpenSource(o);
  std::vector<Event> out;
  while (auto ev = src->Next()) out.push_back(std::move(*ev));
  if (diag) *diag = src->diagnostics();
  return out;
}

TEST(LcmLogSourceTest, DecodesEachRoleByTypeAndChannel) {
  std::vector<uint8_t> b;
  AppendLcmRecord(b, 0, 1000, "LIDAR", test::Encode(Scan(3)));
  AppendLcmRecord(b, 1, 2000, "ODOMETRY", test::Encode(Pose(1, 2, 0.5)));
  AppendLcmRecord(b, 2, 3000, "TRUE_POSE", test::Encode(Pose(3, 4, 0.1)));
  AppendLcmRecord(b, 3, 4000, "SLAM_POSE", test::Encode(Pose(5, 6, 0.2)));
  mbot_lcm_msgs::mbot_encoders_t enc{};
  enc.ticks[0] = 10;
  enc.ticks[1] = -20;
  enc.delta_time = 20000;
  AppendLcmRecord(b, 4, 5000, "MBOT_ENCODERS", test::Encode(enc));
  mbot_lcm_msgs::twist2D_t cmd{};
  cmd.vx = 0.3f;
  cmd.wz = 1.0f;
  AppendLcmRecord(b, 5, 6000, "MBOT_VEL_CMD", test::Encode(cmd));
  const auto path = test::TempPath("roles.log");
  test::WriteBytes(path, b);
  const auto ev = ReadAll(path);
  ASSERT_EQ(ev.size(), 6u);
  EXPECT_EQ(ev[0].kind, EventKind::kLidar);
  const auto& scan = std::get<LidarScan>(ev[0].payload);
  EXPECT_EQ(scan.ranges_m, (std::vector<float>{1, 2, 3}));
  EXPECT_EQ(scan.beam_times_us, (std::vector<int64_t>{1000, 1001, 1002}));
  EXPECT_EQ(ev[0].t_us, 1000);
  EXPECT_EQ(ev[0].stamp_us, 5);
  EXPECT_EQ(ev[1].kind, EventKind::kOdometry);
  EXPECT_EQ(ev[2].kind, EventKind::kGroundTruth);
  EXPECT_EQ(ev[3].kind, EventKind::kReferencePose);
  EXPECT_EQ(ev[4].kind, EventKind::kEncoders);
  EXPECT_EQ(std::get<EncoderTicks>(ev[4].payload).right_ticks, -20);
  EXPECT_EQ(std::get<EncoderTicks>(ev[4].payload).delta_time_us, 20000);
  EXPECT_EQ(ev[5].kind, EventKind::kMotorCommand);
  EXPECT_NEAR(std::get<MotorCommand>(ev[5].payload).velocity.v_m_s, 0.3, 1e-6);
}

TEST(LcmLogSourceTest, CountThatDisagreesWithPayloadIsRejected) {
  std::vector<uint8_t> b;
  auto good = test::Encode(Scan(4));
  auto too_big = good;
  too_big[19] = 200;  // num_ranges = 200, payload holds 4
  auto too_small = good;
  too_small[19] = 2;  // num_ranges = 2: trailing bytes
  auto negative = good;
  negative[16] = 0xff;  // num_ranges < 0
  AppendLcmRecord(b, 0, 1, "LIDAR", too_big);
  AppendLcmRecord(b, 1, 2, "LIDAR", too_small);
  AppendLcmRecord(b, 2, 3, "LIDAR", negative);
  AppendLcmRecord(b, 3, 4, "LIDAR", good);
  auto grid = mbot_legacy::occupancy_grid_t{};
  grid.width = 3;
  grid.height = 3;
  grid.meters_per_cell = 0.05f;
  grid.num_cells = 4;  // disagrees with width * height
  grid.cells.assign(4, 0);
  AppendLcmRecord(b, 4, 5, "SLAM_MAP", test::Encode(grid));
  const auto path = test::TempPath("counts.log");
  test::WriteBytes(path, b);
  SourceDiagnostics d;
  const auto ev = ReadAll(path, &d);
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(std::get<LidarScan>(ev[0].payload).ranges_m.size(), 4u);
  EXPECT_EQ(d.rejected_messages, 4);
}

TEST(LcmLogSourceTest, UnknownFingerprintIsCountedAndSkipped) {
  std::vector<uint8_t> b;
  AppendLcmRecord(b, 0, 1, "MYSTERY", {1, 2, 3, 4, 5, 6, 7, 8, 9});
  AppendLcmRecord(b, 1, 2, "MYSTERY", {1, 2, 3, 4, 5, 6, 7, 8, 9});
  AppendLcmRecord(b, 2, 3, "ODOMETRY", test::Encode(Pose(0, 0, 0)));
  const auto path = test::TempPath("unknown.log");
  test::WriteBytes(path, b);
  SourceOptions o;
  o.path = path;
  auto src = OpenSource(o);
  int n = 0;
  while (src->Next()) ++n;
  EXPECT_EQ(n, 1);
  EXPECT_EQ(src->diagnostics().unknown_messages, 2);
  EXPECT_FALSE(src->channels().at("MYSTERY").decoded);
}

TEST(LcmLogSourceTest, GroundTruthPoseIsRezeroed) {
  std::vector<uint8_t> b;
  AppendLcmRecord(b, 0, 1, "GROUND_TRUTH_POSE", test::Encode(Pose(2, 3, M_PI / 2)));
  AppendLcmRecord(b, 1, 2, "GROUND_TRUTH_POSE", test::Encode(Pose(2, 4, M_PI / 2)));
  const auto path = test::TempPath("gt.log");
  test::WriteBytes(path, b);
  const auto ev = ReadAll(path);
  ASSERT_EQ(ev.size(), 2u);
  const auto p0 = std::get<msgs::Pose2D>(ev[0].payload);
  const auto p1 = std::get<msgs::Pose2D>(ev[1].payload);
  EXPECT_NEAR(p0.x, 0, 1e-6);
  EXPECT_NEAR(p0.theta, 0, 1e-6);
  EXPECT_NEAR(p1.x, 1, 1e-6);  // moved +y in the world = forward for a robot facing +y
  EXPECT_NEAR(p1.y, 0, 1e-6);
}

TEST(LcmLogSourceTest, SlightlyOutOfOrderRecordsAreResorted) {
  std::vector<uint8_t> b;
  AppendLcmRecord(b, 0, 1000, "ODOMETRY", test::Encode(Pose(0, 0, 0)));
  AppendLcmRecord(b, 1, 3000, "ODOMETRY", test::Encode(Pose(2, 0, 0)));
  AppendLcmRecord(b, 2, 2000, "TRUE_POSE", test::Encode(Pose(1, 0, 0)));
  const auto path = test::TempPath("order.log");
  test::WriteBytes(path, b);
  const auto ev = ReadAll(path);
  ASSERT_EQ(ev.size(), 3u);
  EXPECT_EQ(ev[0].t_us, 1000);
  EXPECT_EQ(ev[1].t_us, 2000);
  EXPECT_EQ(ev[2].t_us, 3000);
}

// Found by fuzz_lcm_log: a record stamped near INT64_MIN made the reorder window's subtraction
// overflow. Log stamps outside 1970…2100 are rejected at the edge, like lcm_live does on the bus.
TEST(LcmLogSourceTest, AbsurdRecordStampsAreRejected) {
  std::vector<uint8_t> b;
  AppendLcmRecord(b, 0, 1000, "ODOMETRY", test::Encode(Pose(0, 0, 0)));
  AppendLcmRecord(b, 1, INT64_MIN + 7, "ODOMETRY", test::Encode(Pose(1, 0, 0)));
  AppendLcmRecord(b, 2, -5, "ODOMETRY", test::Encode(Pose(1, 0, 0)));
  AppendLcmRecord(b, 3, 2000, "ODOMETRY", test::Encode(Pose(2, 0, 0)));
  const auto path = test::TempPath("absurd_stamps.log");
  test::WriteBytes(path, b);
  SourceDiagnostics diag;
  const auto ev = ReadAll(path, &diag);
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[1].t_us, 2000);
  EXPECT_EQ(diag.rejected_messages, 2);
}

TEST(LcmLogSourceTest, RandomCorruptionNeverCrashes) {
  std::vector<uint8_t> clean;
  for (int i = 0; i < 50; ++i) {
    AppendLcmRecord(clean, i, 1000 * i, "LIDAR", test::Encode(Scan(i % 7)));
    AppendLcmRecord(clean, i, 1000 * i + 1, "ODOMETRY", test::Encode(Pose(i, 0, 0)));
  }
  uint32_t state = 12345;
  for (int trial = 0; trial < 200; ++trial) {
    auto bytes = clean;
    for (int k = 0; k < 10; ++k) {
      state = state * 1664525u + 1013904223u;
      bytes[state % bytes.size()] ^= static_cast<uint8_t>(state >> 24);
    }
    state = state * 1664525u + 1013904223u;
    bytes.resize(bytes.size() - state % 64);
    const auto path = test::TempPath("fuzz.log");
    test::WriteBytes(path, bytes);
    SourceDiagnostics d;
    const auto ev = ReadAll(path, &d);
    EXPECT_LE(ev.size(), 100u);
  }
}

}  // namespace
}  // namespace mbot::lcmio
