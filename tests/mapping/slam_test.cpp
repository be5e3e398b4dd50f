// mapping::Slam in each of its four modes, on the room fixture: the robot drives 1 m along x while a
// lidar scans the room; odometry is exact unless a test says otherwise.
#include "mbot/mapping/slam.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "room_fixture.hpp"

namespace mbot::mapping {
namespace {

using motion::Pose2D;

SlamOptions Options(SlamMode mode) {
  SlamOptions o;
  o.mode = mode;
  o.filter.particles = 300;
  o.mapper.width_m = 6.0, o.mapper.height_m = 6.0;
  return o;
}

// Drives from (-0.5, -0.5, 0) to (0.5, -0.5, 0) in 5 cm steps; returns the last estimate.
Pose2D Drive(Slam& slam, const Room& room, bool give_reference, const Pose2D& odometry_offset = {}) {
  SlamStep step;
  for (int i = 0; i <= 20; ++i) {
    const Pose2D truth{-0.5 + 0.05 * i, -0.5, 0.0};
    const Pose2D odometry = odometry_offset.Compose(truth);
    step = slam.ProcessScan(MarchScan(room.map, truth), odometry, give_reference ? &truth : nullptr);
  }
  return step.pose;
}

TEST(Slam, LocalizationTracksTheRobotInTheKnownMap) {
  const Room room;
  Slam slam(Options(SlamMode::kLocalization), 1);
  slam.SetMap(room.map);
  slam.Initialize({-0.47, -0.53, 0.03}, {-0.5, -0.5, 0}, 0.05, 0.05);  // 3 cm and 2 degrees off
  const Pose2D end = Drive(slam, room, false);
  EXPECT_NEAR(end.x, 0.5, 0.03);
  EXPECT_NEAR(end.y, -0.5, 0.03);
  EXPECT_NEAR(end.theta, 0.0, 0.03);
  EXPECT_EQ(slam.map(), room.map) << "localization must not change the known map";
  EXPECT_GT(slam.filter_updates(), 0);
}

TEST(Slam, MappingOnlyDrawsTheWallsAtTheGivenPoses) {
  const Room room;
  Slam slam(Options(SlamMode::kMappingOnly), 1);
  slam.Initialize({-0.5, -0.5, 0}, {-0.5, -0.5, 0});
  const Pose2D end = Drive(slam, room, true);
  EXPECT_NEAR(end.x, 0.5, 1e-9);  // the given pose
  int cx, cy;
  slam.map().WorldToCell(1.96, 0.0, &cx, &cy);  // the east wall (x 1.95 to 2.0)
  EXPECT_GT(slam.map().at(cx, cy), 0);
  slam.map().WorldToCell(1.0, 0.0, &cx, &cy);  // the middle of the room
  EXPECT_LT(slam.map().at(cx, cy), 0);
  EXPECT_EQ(slam.filter_updates(), 0);
}

// Full SLAM from an empty map, with odometry whose heading drifts 0.3 degrees per 5 cm step (6
// degrees over the drive): the scans against its own map hold the estimate to the truth.
TEST(Slam, FullSlamCorrectsDriftingOdometryWithItsOwnMap) {
  const Room room;
  SlamOptions o = Options(SlamMode::kFullSlam);
  Slam slam(o, 3);
  slam.Initialize({-0.5, -0.5, 0}, {-0.5, -0.5, 0});
  SlamStep step;
  Pose2D odometry{-0.5, -0.5, 0};
  for (int i = 1; i <= 20; ++i) {
    const Pose2D truth{-0.5 + 0.05 * i, -0.5, 0.0};
    odometry = odometry.Compose(Pose2D{0.05, 0.0, 0.3 * M_PI / 180});
    step = slam.ProcessScan(MarchScan(room.map, truth), odometry);
  }
  EXPECT_NEAR(step.pose.x, 0.5, 0.05);
  EXPECT_NEAR(step.pose.y, -0.5, 0.03) << "odometry alone ends at y = " << odometry.y;
  EXPECT_NEAR(step.pose.theta, 0.0, 1.5 * M_PI / 180)
      << "odometry alone ends at " << odometry.theta * 180 / M_PI << " deg";
  EXPECT_GT(std::abs(odometry.theta), 5.0 * M_PI / 180);
}

// A corrupt scan on a faulty bus (its stamp off, so it is placed where the robot was not): one
// whose fit to the map collapses is not mapped, and the map keeps no room that is not there. A run
// of them longer than gate_max_scans is mapped (the map must follow a world that changed).
TEST(Slam, FullSlamDoesNotMapAScanWhoseFitCollapses) {
  const Room room;
  Slam slam(Options(SlamMode::kFullSlam), 3);
  slam.Initialize({-0.5, -0.5, 0}, {-0.5, -0.5, 0});
  Pose2D truth;
  for (int i = 0; i <= 14; ++i) {
    truth = {-0.5 + 0.05 * i, -0.5, 0.0};
    EXPECT_FALSE(slam.ProcessScan(MarchScan(room.map, truth), truth).gated);
  }
  const OccupancyGrid before = slam.map();
  const Pose2D elsewhere{0.9, 0.6, 1.2};  // what the corrupt scan saw, from where it really was
  const SlamStep bad = slam.ProcessScan(MarchScan(room.map, elsewhere), truth);
  EXPECT_TRUE(bad.gated);
  EXPECT_EQ(slam.map(), before);
  EXPECT_EQ(slam.scans_gated(), 1);
  EXPECT_FALSE(slam.ProcessScan(MarchScan(room.map, truth), truth).gated);  // the next good one is mapped
  for (int k = 0; k < 3; ++k) EXPECT_TRUE(slam.ProcessScan(MarchScan(room.map, elsewhere), truth).gated);
  EXPECT_FALSE(slam.ProcessScan(MarchScan(room.map, elsewhere), truth).gated);  // the fourth in a row
  EXPECT_EQ(slam.scans_gated(), 4);
  // Off, nothing is gated.
  SlamOptions off = Options(SlamMode::kFullSlam);
  off.gate_fit_ratio = 0;
  Slam plain(off, 3);
  plain.Initialize({-0.5, -0.5, 0}, {-0.5, -0.5, 0});
  for (int i = 0; i <= 14; ++i)
    plain.ProcessScan(MarchScan(room.map, {-0.5 + 0.05 * i, -0.5, 0.0}), {-0.5 + 0.05 * i, -0.5, 0.0});
  EXPECT_FALSE(plain.ProcessScan(MarchScan(room.map, elsewhere), truth).gated);
}

TEST(Slam, ActionOnlyFollowsOdometry) {
  const Room room;
  Slam slam(Options(SlamMode::kActionOnly), 1);
  slam.Initialize({-0.5, -0.5, 0}, {-0.5, -0.5, 0});
  const Pose2D end = Drive(slam, room, false);
  EXPECT_NEAR(end.x, 0.5, 0.05);
  EXPECT_NEAR(end.y, -0.5, 0.05);
}

// A person's switches (the viewer): mapping off keeps the map; localization off follows odometry
// (here drifting 0.3 degrees a step, uncorrected); clearing forgets every cell; and what a mode
// cannot do is refused, saying why.
TEST(Slam, MappingAndLocalizationCanBeSwitchedAndTheMapCleared) {
  const Room room;
  Slam slam(Options(SlamMode::kFullSlam), 3);
  slam.Initialize({-0.5, -0.5, 0}, {-0.5, -0.5, 0});
  slam.ProcessScan(MarchScan(room.map, {-0.5, -0.5, 0}), {-0.5, -0.5, 0});
  const OccupancyGrid first = slam.map();
  slam.SetMapping(false);
  slam.SetLocalization(false);
  SlamStep step;
  Pose2D odometry{-0.5, -0.5, 0};
  for (int i = 1; i <= 20; ++i) {
    odometry = odometry.Compose(Pose2D{0.05, 0.0, 0.3 * M_PI / 180});
    step = slam.ProcessScan(MarchScan(room.map, {-0.5 + 0.05 * i, -0.5, 0.0}), odometry);
  }
  EXPECT_EQ(slam.map(), first) << "mapping off: the map must stay as it was";
  // The pose is odometry's from the first scan's estimate on (the filter's first update may have
  // moved that by a little): 6 degrees of drift stay, where localization corrects them to 1.5.
  EXPECT_NEAR(step.pose.theta, odometry.theta, 0.5 * M_PI / 180) << "localization off: the pose is odometry's";
  EXPECT_NEAR(step.pose.x, odometry.x, 0.02);
  slam.SetMapping(true);
  slam.ProcessScan(MarchScan(room.map, {0.5, -0.5, 0}), odometry);
  EXPECT_FALSE(slam.map() == first) << "mapping on again: the scan went into the map";
  slam.ClearMap();
  int known = 0;
  for (int8_t c : slam.map().cells()) known += c != 0;
  EXPECT_EQ(known, 0);
  EXPECT_EQ(slam.map().width(), first.width());

  Slam localization(Options(SlamMode::kLocalization), 1);
  localization.SetMap(room.map);
  EXPECT_THROW(localization.SetMapping(true), std::invalid_argument);
  EXPECT_THROW(localization.ClearMap(), std::invalid_argument);
  Slam mapping_only(Options(SlamMode::kMappingOnly), 1);
  EXPECT_THROW(mapping_only.SetLocalization(false), std::invalid_argument);
}

TEST(Slam, StatusNamesWhatThePoseIsWorth) {
  FilterStatus s;
  EXPECT_EQ(StateOf(SlamMode::kFullSlam, s), SlamState::kMapping);
  s.converged = false;
  EXPECT_EQ(StateOf(SlamMode::kLocalization, s), SlamState::kLocalizing);
  s.converged = true;
  EXPECT_EQ(StateOf(SlamMode::kLocalization, s), SlamState::kLocalized);
  s.lost = true;
  EXPECT_EQ(StateOf(SlamMode::kLocalization, s), SlamState::kLost);
  EXPECT_STREQ(ToString(SlamState::kLocalized), "localized");
}

}  // namespace
}  // namespace mbot::mapping
