// SLAM's front end and policies on a synthetic event stream (libs/mapping: slam_session.hpp): which
// channels it takes, where it places each message in time, encoder odometry, scans waiting for
// their poses, memory kept bounded, and what a session publishes.
#include "mbot/mapping/slam_session.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace mbot::mapping {
namespace {

using msgs::Event;
using msgs::EventKind;

Event Odometry(int64_t t_us, double x, const std::string& channel = "MBOT_ODOMETRY", int64_t stamp_us = 0) {
  return Event{t_us, stamp_us, channel, EventKind::kOdometry, msgs::Pose2D{x, 0, 0}};
}

// A scan of a 4 m × 4 m box centred on the origin from (x, 0), 180 beams.
msgs::LidarScan BoxScan(double x) {
  msgs::LidarScan s;
  for (int i = 0; i < 180; ++i) {
    const double a = -M_PI + 2 * M_PI * i / 180;
    const double c = std::cos(a), d = std::sin(a);
    const double tx = c > 1e-9 ? (2 - x) / c : c < -1e-9 ? (-2 - x) / c : 1e9;
    const double ty = d > 1e-9 ? 2 / d : d < -1e-9 ? -2 / d : 1e9;
    s.ranges_m.push_back(static_cast<float>(std::min(tx, ty)));
    s.angles_rad.push_back(static_cast<float>(a));
  }
  s.max_range_m = 8;
  return s;
}

Event Scan(int64_t t_us, double x) { return Event{t_us, t_us, "LIDAR", EventKind::kLidar, BoxScan(x)}; }

TEST(SlamInputs, TakesTheFirstChannelOfAKindAndPlacesScansOnceTheirPosesArrived) {
  SlamSessionOptions o;
  SlamInputs in(o, 1);
  EXPECT_TRUE(in.Add(Odometry(0, 0.0)));
  EXPECT_TRUE(in.Add(Odometry(10'000, 5.0, "ODOMETRY")));  // a second odometry channel: ignored
  EXPECT_TRUE(in.Add(Scan(100'000, 0.0)));
  EXPECT_FALSE(in.Add(Event{100'000, 0, "MISSION_STATUS", EventKind::kMissionStatus, msgs::MissionStatus{}}));
  ASSERT_EQ(in.odometry().size(), 1u);
  EXPECT_EQ(in.ReadyScan(false), nullptr);  // no odometry at or after the scan's time yet
  in.Add(Odometry(120'000, 0.12));
  const SlamInputs::Scan* s = in.ReadyScan(false);
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->t_us, 100'000);
  EXPECT_EQ(s->previous_us, -1);
  in.PopScan();
  in.Add(Scan(200'000, 0.0));
  EXPECT_EQ(in.ReadyScan(false), nullptr);
  ASSERT_NE(in.ReadyScan(true), nullptr);  // at the end of the stream it goes anyway
  EXPECT_EQ(in.ReadyScan(true)->previous_us, 100'000);
  EXPECT_EQ(in.lidar_channel(), "LIDAR");
}

TEST(SlamInputs, StampsThatShareTheLogsClockPlaceTheirMessagesAndOthersKeepTheirArrival) {
  SlamSessionOptions o;
  o.time_base = "auto";
  SlamInputs in(o, 1);
  // Odometry stamped 30 ms before it arrived (same clock): placed at its stamp.
  in.Add(Odometry(1'000'000, 0.0, "MBOT_ODOMETRY", 970'000));
  // Ground truth stamped on another clock (seconds since boot): placed at its arrival.
  in.Add(Event{1'000'000, 50'000'000, "TRUE_POSE", EventKind::kGroundTruth, msgs::Pose2D{1, 2, 0}});
  ASSERT_EQ(in.odometry().size(), 1u);
  EXPECT_EQ(in.odometry()[0].t_us, 970'000);
  ASSERT_EQ(in.ground_truth().size(), 1u);
  EXPECT_EQ(in.ground_truth()[0].t_us, 1'000'000);
  // A corrupt stamp far from its arrival on a same-clock channel: placed at its arrival.
  in.Add(Odometry(1'100'000, 0.1, "MBOT_ODOMETRY", 9'100'000));
  ASSERT_EQ(in.odometry().size(), 2u);
  EXPECT_EQ(in.odometry()[1].t_us, 1'100'000);
}

TEST(SlamInputs, EncoderTicksIntegrateToOdometry) {
  SlamSessionOptions o;
  o.encoder_odometry = true;
  o.wheels = {0.001, 0.001, 0.15};  // 1 mm per tick
  SlamInputs in(o, 1);
  in.Add(Odometry(0, 9.0));  // an odometry channel is not used then
  for (int k = 0; k <= 10; ++k) {
    in.Add(Event{k * 100'000, 0, "MBOT_ENCODERS", EventKind::kEncoders, msgs::EncoderTicks{k * 100, k * 100}});
  }
  ASSERT_EQ(in.odometry().size(), 11u);
  EXPECT_NEAR(in.odometry().back().pose.x, 1.0, 1e-9);  // 1000 ticks of 1 mm, straight ahead
  EXPECT_NEAR(in.odometry().back().pose.y, 0.0, 1e-9);
}

TEST(SlamInputs, TrimmingKeepsTheNeighboursOfTheTimeAsked) {
  SlamSessionOptions o;
  SlamInputs in(o, 1);
  for (int k = 0; k < 10'000; ++k) in.Add(Odometry(k * 1000, k * 1e-3));
  in.TrimBefore(9'000'000);
  ASSERT_LT(in.odometry().size(), 10'000u);
  EXPECT_LE(in.odometry().front().t_us, 9'000'000);  // the pose before the time asked is kept
  in.TrimBefore(9'000'500);                          // fewer than a batch due: nothing moves
  EXPECT_LE(in.odometry().front().t_us, 9'000'000);
}

// Graph SLAM's recovery asks whether the odometry since the last scan is doubtful: a gap longer
// than the limit is reported, with its length, to every scan whose step from the last scan it
// overlaps, and not to a scan whose step starts where the gap ended (the last scan was told).
TEST(SlamInputs, AnOdometryGapIsDoubtfulOnceWithItsLength) {
  SlamSessionOptions o;
  SlamInputs in(o, 1);
  for (int k = 0; k <= 10; ++k) in.Add(Odometry(k * 100'000, k * 0.01));   // 0 to 1 s
  for (int k = 25; k <= 30; ++k) in.Add(Odometry(k * 100'000, k * 0.01));  // a 1.5 s gap, then on
  const int64_t limit = 1'000'000;
  EXPECT_FALSE(in.PosesDoubtful(500'000, 900'000, limit).doubtful);
  const OdometryDoubt across = in.PosesDoubtful(900'000, 2'600'000, limit);
  EXPECT_TRUE(across.doubtful);
  EXPECT_NEAR(across.unobserved_s, 1.5, 1e-9);
  // A scan inside the gap: the gap is still ahead of it, and counts; so it does for the next scan,
  // whose step from inside the gap crosses the rest of it.
  EXPECT_TRUE(in.PosesDoubtful(900'000, 1'200'000, limit).doubtful);
  EXPECT_TRUE(in.PosesDoubtful(1'200'000, 2'600'000, limit).doubtful);
  // The scan after: the gap ended at the last scan, which was told.
  EXPECT_FALSE(in.PosesDoubtful(2'500'000, 2'600'000, limit).doubtful);
  EXPECT_FALSE(in.PosesDoubtful(2'600'000, 2'700'000, limit).doubtful);
  EXPECT_FALSE(in.PosesDoubtful(900'000, 2'600'000, 2'000'000).doubtful);  // shorter than a longer limit
}

TEST(SlamSession, PublishesThePoseEveryScanTheStatusOnChangeAndTheMapEveryKthScan) {
  SlamSessionOptions o;
  o.slam.mode = SlamMode::kFullSlam;
  o.slam.filter.particles = 50;
  o.publish_map_every = 3;
  o.publish_particles_every = 2;
  o.particles_every = 4;
  SlamSession session(o, 7, std::nullopt);
  std::vector<Event> out;
  int poses = 0, maps = 0, statuses = 0, particles = 0;
  auto count = [&] {
    for (const Event& e : out) {
      poses += e.channel == "SLAM_POSE" && e.kind == EventKind::kPoseEstimate;
      maps += e.channel == "SLAM_MAP" && e.kind == EventKind::kMap;
      statuses += e.channel == "SLAM_STATUS";
      particles += e.channel == "SLAM_PARTICLES";
    }
    out.clear();
  };
  for (int k = 0; k < 12; ++k) {
    const double x = 0.02 * k;
    session.Add(Odometry(k * 100'000, x), &out);
    session.Add(Scan(k * 100'000 + 50'000, x), &out);
    count();
  }
  session.Add(Odometry(1'300'000, 0.26), &out);
  session.Finish(&out);
  count();
  const size_t scans = session.scans_processed();
  EXPECT_EQ(scans, 12u);
  EXPECT_EQ(poses, 12);
  EXPECT_EQ(statuses, 1);                                   // "mapping", once
  EXPECT_EQ(maps, 1 + 12 / 3);                              // the first scan's, then every third
  EXPECT_EQ(particles, 12 / 2);                             // every second scan
  EXPECT_EQ(session.particle_snapshots().size(), 3u * 50);  // scans 1, 5, 9
  EXPECT_EQ(session.skipped_scans(), 0);
  // The robot drove 0.22 m along x: SLAM follows.
  EXPECT_NEAR(session.last_record()->slam.x, 0.22, 0.05);
}

TEST(SlamSession, RecordsStreamOutAsTheirTruthArrivesSoALongRunHoldsFew) {
  SlamSessionOptions o;
  o.slam.mode = SlamMode::kFullSlam;
  o.slam.filter.particles = 20;
  SlamSession session(o, 3, std::nullopt);
  std::vector<mapping::ScanRecord> got;
  size_t most_held = 0;
  session.StreamRecords([&](const ScanRecord& r) { got.push_back(r); });
  std::vector<Event> out;
  for (int k = 0; k < 400; ++k) {
    const double x = 0.001 * k;
    session.Add(Odometry(k * 100'000, x), &out);
    session.Add(Event{k * 100'000 + 20'000, 0, "TRUE_POSE", EventKind::kGroundTruth, msgs::Pose2D{x, 0.5, 0}}, &out);
    session.Add(Scan(k * 100'000 + 50'000, x), &out);
    most_held = std::max(most_held, session.records().size());
  }
  // Streamed during the run, not at its end. No reference series ever started, so a record waits
  // for one until it is 4 × max_pose_gap_s + 1 s = 3 s old: ~30 scans held, however long the run.
  EXPECT_GT(got.size(), 360u);
  EXPECT_LE(most_held, 32u);
  session.Finish(&out);
  ASSERT_EQ(got.size(), session.scans_processed());
  EXPECT_TRUE(session.records().empty());
  for (size_t i = 0; i < got.size(); ++i) {
    if (i > 0) {
      EXPECT_GT(got[i].t_us, got[i - 1].t_us);
    }
    ASSERT_TRUE(got[i].truth) << "record " << i;
    EXPECT_NEAR(got[i].truth->y, 0.5, 1e-9);
  }
}

TEST(SlamSession, RecordsWaitForATruthThatStoppedOnlyAFewSeconds) {
  SlamSessionOptions o;
  o.slam.mode = SlamMode::kFullSlam;
  o.slam.filter.particles = 20;
  SlamSession session(o, 3, std::nullopt);
  size_t released = 0, with_truth = 0;
  session.StreamRecords([&](const ScanRecord& r) { ++released, with_truth += r.truth.has_value(); });
  std::vector<Event> out;
  for (int k = 0; k < 300; ++k) {  // the truth stops after 5 s of 30
    session.Add(Odometry(k * 100'000, 0.001 * k), &out);
    if (k < 50) session.Add(Event{k * 100'000, 0, "TRUE_POSE", EventKind::kGroundTruth, msgs::Pose2D{}}, &out);
    session.Add(Scan(k * 100'000 + 50'000, 0.001 * k), &out);
  }
  // max_pose_gap_s = 0.5: a record is given up 4 × 0.5 + 1 = 3 s behind the newest scan.
  EXPECT_LE(session.records().size(), 32u);
  EXPECT_GE(released, 260u);
  session.Finish(&out);
  EXPECT_EQ(released, session.scans_processed());
  EXPECT_GE(with_truth, 50u);
  EXPECT_LE(with_truth, 55u);  // the last truth pose holds for max_pose_gap_s
}

TEST(SlamSession, ACheckpointIsDueEveryIntervalOfTheStreamsTime) {
  SlamSessionOptions o;
  o.slam.mode = SlamMode::kFullSlam;
  o.slam.filter.particles = 20;
  o.checkpoint_every_s = 0.5;
  SlamSession session(o, 7, std::nullopt);
  std::vector<double> at;
  session.OnCheckpoint([&](const SlamCheckpointState& c, const OccupancyGrid& map) {
    at.push_back(c.t_s);
    EXPECT_GT(map.CountCells().occupied, 0);
  });
  std::vector<Event> out;
  for (int k = 0; k < 20; ++k) {
    session.Add(Odometry(k * 100'000, 0.0), &out);
    session.Add(Scan(k * 100'000 + 50'000, 0.0), &out);
  }
  session.Finish(&out);
  ASSERT_EQ(at.size(), 4u);  // scans at 0.05, 0.55, 1.05, 1.55 s
  EXPECT_NEAR(at[0], 0.05, 1e-9);
  EXPECT_NEAR(at[1], 0.55, 1e-9);
}

}  // namespace
}  // namespace mbot::mapping
