#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "carmen_source.hpp"
#include "mbot/drivers/source_options.hpp"
#include "test_util.hpp"

namespace mbot::drivers {

using namespace msgs;  // the event vocabulary
namespace {

TEST(CarmenSourceTest, BeamGeometryFollowsCarmen) {
  double start, inc;
  CarmenSource::GuessBeamGeometry(180, &start, &inc);
  EXPECT_NEAR(inc * 180 / M_PI, 1.0, 1e-12);
  EXPECT_NEAR(start * 180 / M_PI, -89.5, 1e-9);
  CarmenSource::GuessBeamGeometry(361, &start, &inc);
  EXPECT_NEAR(inc * 180 / M_PI, 0.5, 1e-12);
  EXPECT_NEAR(start * 180 / M_PI, -90.0, 1e-9);
}

TEST(CarmenSourceTest, ParsesOldAndNewLinesKeepingPoseAndOdometryApart) {
  const auto path = test::TempPath("t.log");
  std::ofstream(path) << "# comment\n"
                         "PARAM robot_front_laser_max 50 nohost 0\n"
                         "ODOM 1 2 0.5 0 0 0 10.25 host 10.25\n"
                         "FLASER 3 1.0 2.0 60.0 0.1 0.2 0.3 0.4 0.5 0.6 11.5 host 11.5\n"
                         "ROBOTLASER1 0 -1.5708 3.1416 1.5708 30 0.01 0 3 1 2 3 0 0.2 0 0 0 0 0 0 0 0 0 0 12.0 h 12.0\n"
                         "FLASER 2 1.0 bogus 0 0 0 0 0 0 13 host 13\n"
                         "NEFF 1 2\n";
  SourceOptions o;
  o.path = path;
  auto src = OpenSource(o);
  std::vector<Event> ev;
  while (auto e = src->Next()) ev.push_back(std::move(*e));
  ASSERT_EQ(ev.size(), 6u);
  EXPECT_EQ(ev[0].channel, "ODOM");
  EXPECT_EQ(ev[0].t_us, 10250000);
  EXPECT_EQ(ev[1].kind, EventKind::kLidar);
  const auto& scan = std::get<LidarScan>(ev[1].payload);
  EXPECT_EQ(scan.ranges_m.size(), 3u);
  EXPECT_FLOAT_EQ(scan.max_range_m, 50.0f);  // from PARAM robot_front_laser_max
  EXPECT_EQ(ev[2].kind, EventKind::kReferencePose);
  EXPECT_NEAR(std::get<msgs::Pose2D>(ev[2].payload).x, 0.1, 1e-12);
  EXPECT_EQ(ev[3].kind, EventKind::kOdometry);
  EXPECT_NEAR(std::get<msgs::Pose2D>(ev[3].payload).x, 0.4, 1e-12);
  EXPECT_EQ(ev[4].channel, "ROBOTLASER1.odom");  // its robot pose fields: the odometry at the scan
  EXPECT_EQ(ev[4].kind, EventKind::kOdometry);
  EXPECT_NEAR(std::get<msgs::Pose2D>(ev[4].payload).x, 0.0, 1e-12);
  EXPECT_EQ(ev[5].channel, "ROBOTLASER1");
  const auto& rl = std::get<LidarScan>(ev[5].payload);
  EXPECT_NEAR(rl.angles_rad[2] - rl.angles_rad[1], 1.5708, 1e-5);
  EXPECT_NEAR(rl.sensor_pose.x, 0.2, 1e-9);
  EXPECT_EQ(src->diagnostics().rejected_messages, 1);  // the 'bogus' line
}

// Non-finite numbers are rejected where they enter, with the line; a non-finite range is a beam
// without a return; a stamp slightly before the log's zero (the Freiburg 079 log has one) is kept.
TEST(CarmenSourceTest, NonFiniteNumbersAreRejectedWithTheirLine) {
  const auto path = test::TempPath("nan.log");
  std::ofstream(path) << "ODOM 1 2 0.5 0 0 0 nan host 1\n"
                         "ODOM 1 2 inf 0 0 0 2 host 2\n"
                         "ODOM 1 2 0.5 0 0 0 1e300 host 3\n"
                         "ODOM 1 2 0.5 0 0 0 -0.9 host 4\n"
                         "FLASER 2 1.0 inf 0 0 0 0 0 0 5 host 5\n";
  SourceOptions o;
  o.path = path;
  auto src = OpenSource(o);
  std::vector<Event> ev;
  while (auto e = src->Next()) ev.push_back(std::move(*e));
  std::vector<int64_t> odom_times;
  const LidarScan* scan = nullptr;
  for (const Event& e : ev) {
    if (e.channel == "ODOM") odom_times.push_back(e.t_us);
    if (e.kind == EventKind::kLidar) scan = &std::get<LidarScan>(e.payload);
  }
  EXPECT_EQ(odom_times, std::vector<int64_t>{-900000});
  ASSERT_NE(scan, nullptr);
  EXPECT_EQ(scan->ranges_m[1], 0.0f);
  EXPECT_EQ(src->diagnostics().rejected_messages, 3);
}

// A count that does not describe its line leaves tokens over: the record is rejected, not half read.
TEST(CarmenSourceTest, TokensBeyondTheRecordRejectIt) {
  const auto path = test::TempPath("trailing.log");
  std::ofstream(path) << "ODOM 1 2 0.5 0 0 0 1 host 1\n"
                         "ODOM 1 2 0.5 0 0 0 2 host 2 extra\n"
                         "FLASER 2 1.0 2.0 3.0 0 0 0 0 0 0 3 host 3\n"  // three ranges, count says two
                         "ODOM 1 2 0.5 0 0 0 4\n";                      // no host or logger stamp: fine
  SourceOptions o;
  o.path = path;
  auto src = OpenSource(o);
  int odom = 0, lidar = 0;
  while (auto e = src->Next()) {
    odom += e->channel == "ODOM";
    lidar += e->kind == EventKind::kLidar;
  }
  EXPECT_EQ(odom, 2);
  EXPECT_EQ(lidar, 0);
  EXPECT_EQ(src->diagnostics().rejected_messages, 2);
}

// Old Mac line ends (CR alone) and Windows ones (CRLF) read like LF: every record, numbered.
TEST(CarmenSourceTest, EveryLineEndIsALineEnd) {
  for (const char* end : {"\r", "\r\n", "\n"}) {
    const auto path = test::TempPath("cr.log");
    std::ofstream(path) << "ODOM 1 2 0.5 0 0 0 1 host 1" << end << "ODOM 1 2 0.5 0 0 0 2 host 2" << end
                        << "ODOM 1 2 bogus 0 0 0 3 host 3" << end;
    SourceOptions o;
    o.path = path;
    auto src = OpenSource(o);
    int n = 0;
    while (src->Next()) ++n;
    EXPECT_EQ(n, 2) << "line end " << (end[0] == '\r' && !end[1] ? "CR" : end[1] ? "CRLF" : "LF");
    EXPECT_EQ(src->diagnostics().rejected_messages, 1);
  }
}

TEST(CarmenSourceTest, ReadsGzip) {
  const auto path = test::TempPath("t2.log");
  std::ofstream(path) << "ODOM 1 2 0.5 0 0 0 10.25 host 10.25\n";
  ASSERT_EQ(std::system(("gzip -f " + path).c_str()), 0);
  SourceOptions o;
  o.path = path + ".gz";
  EXPECT_EQ(DetectFormat(o.path), "carmen");
  auto src = OpenSource(o);
  EXPECT_TRUE(src->Next());
  EXPECT_FALSE(src->Next());
}

}  // namespace
}  // namespace mbot::drivers
