// The competition's judge (libs/sim/referee): its rubric, and the Warehouse's stops judged from the
// true pose, asserted on the Score it returns.
#include "mbot/sim/referee.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace mbot::sim {
namespace {

namespace warehouse = mission::warehouse;
using motion::Pose2D;

World WarehouseWorld() { return World::Load(std::string(MBOT_SOURCE_DIR) + "/datasets/arenas/warehouse.arena"); }

// Feeds a warehouse referee (seed 5) true poses at 100 Hz.
class Harness {
 public:
  Harness() : referee_({CompetitionEvent::kWarehouse, 720.0, 0.5}, WarehouseWorld(), 5) {}
  void Stand(const Pose2D& p, double seconds) {
    for (int i = 0; i < seconds * 100; ++i, t_ += 10'000) {
      referee_.Tick(t_);
      referee_.OnTruePose(t_, p);
    }
  }
  Referee& referee() { return referee_; }

 private:
  Referee referee_;
  int64_t t_ = 0;
};

// Standing 2 s at a later stop marks the one before it missed, so that delivery fails while the
// next still counts (level 1 reached, level 2 not).
TEST(RefereeWarehouse, AMissedStopFailsItsDeliveryAndTheNextStillCounts) {
  Harness h;
  const auto& stops = h.referee().stops();
  ASSERT_EQ(stops.size(), 14u);
  h.Stand(stops[0].pose, 2.2);                                // target of delivery 1: done
  h.Stand({stops[1].pose.x + 0.3, stops[1].pose.y, 0}, 1.0);  // near its drop-off, but not at it
  h.Stand(stops[2].pose, 2.2);                                // on to delivery 2: drop-off 1 missed
  h.Stand(stops[3].pose, 1.0);                                // too short to count...
  h.Stand({0, 0, 0}, 0.01);
  h.Stand(stops[3].pose, 2.2);  // ...the second visit does
  const Score s = h.referee().Judge();
  EXPECT_EQ(s.levels_reached, 1);
  ASSERT_EQ(s.stops.size(), 14u);
  EXPECT_TRUE(s.stops[0].done_at_s.has_value());
  EXPECT_FALSE(s.stops[0].missed);
  EXPECT_TRUE(s.stops[1].missed);
  EXPECT_FALSE(s.stops[1].done_at_s.has_value());
  EXPECT_TRUE(s.stops[2].done_at_s.has_value());
  EXPECT_TRUE(s.stops[3].done_at_s.has_value());
  EXPECT_NEAR(*s.stops[3].done_at_s, 2.2 + 1.0 + 2.2 + 1.0 + 0.01 + 2.0, 0.03);
  EXPECT_FALSE(s.stops[4].done_at_s.has_value());
  EXPECT_FALSE(s.stops[4].missed);  // not reached
  EXPECT_EQ(s.total, 100);          // level 1 only; never localized
}

// The drop-offs repeat (stop 5 is drop-off 1 again): standing on at drop-off 1 after delivering to
// it does not count as the later visit, and does not mark the stops between missed.
TEST(RefereeWarehouse, StayingAtADropOffDoesNotCountItsNextVisit) {
  Harness h;
  const auto& stops = h.referee().stops();
  ASSERT_EQ(stops[5].pose.x, stops[1].pose.x);
  h.Stand(stops[0].pose, 2.2);
  h.Stand(stops[1].pose, 6.0);
  const Score s = h.referee().Judge();
  EXPECT_TRUE(s.stops[1].done_at_s.has_value());
  for (int k = 2; k <= 6; ++k) {
    EXPECT_FALSE(s.stops[k].done_at_s.has_value()) << k;
    EXPECT_FALSE(s.stops[k].missed) << k;
  }
}

TEST(RefereeRubric, PoseAndLapTiers) {
  EXPECT_EQ(PosePoints({0.02, 0.029, 14}), 100);
  EXPECT_EQ(PosePoints({0.02, 0.03, 14}), 75);
  EXPECT_EQ(PosePoints({0.02, 0.02, 20}), 50);
  EXPECT_EQ(PosePoints({0.19, 0.0, 44}), 25);
  EXPECT_EQ(PosePoints({0.2, 0.0, 0}), 0);
  EXPECT_EQ(LapPoints(14.99), 100);
  EXPECT_EQ(LapPoints(15.0), 75);
  EXPECT_EQ(LapPoints(29.9), 50);
  EXPECT_EQ(LapPoints(30.0), 0);
}

// A speed run that comes back 1 cm off and a map that is the world's own truth: full points; the
// run ends finish_delay_s after the mission completes; without the mission, at the time limit.
TEST(RefereeSpeedRun, ScoresAPerfectLapAndEndsAfterTheMission) {
  const World world = World::Load(std::string(MBOT_SOURCE_DIR) + "/datasets/arenas/convex_circuit.arena");
  Referee r({CompetitionEvent::kSpeedRun, 120.0, 0.5}, world, 1);
  const Pose2D start = world.PosesLabelled("start").at(0);
  // The map SLAM would have built, in the start frame: the truth moved into it.
  const mapping::OccupancyGrid& t = world.truth();
  auto map = std::make_shared<mapping::OccupancyGrid>(t.width(), t.height(), t.resolution(), t.origin_x() - start.x,
                                                      t.origin_y() - start.y);
  map->cells() = t.cells();
  r.Tick(0);
  r.OnTruePose(0, start);
  r.OnMap(map);
  r.Tick(14'000'000);
  r.OnTruePose(14'000'000, {start.x + 0.01, start.y, start.theta});
  r.OnMissionStatus(14'000'000, {mission::MissionState::kCompleted, "circuit driven"});
  // An older status that a faulty link delivered late does not undo the completion.
  r.OnMissionStatus(14'100'000, {mission::MissionState::kReturningHome, "returning home"});
  EXPECT_FALSE(r.StopReason(14'000'000));
  EXPECT_TRUE(r.StopReason(14'600'000));
  EXPECT_FALSE(r.StopReason(14'700'000));  // once
  const Score s = r.Judge();
  ASSERT_TRUE(s.scored);
  EXPECT_TRUE(s.completed);
  EXPECT_NEAR(s.time_s, 14.0, 1e-9);
  ASSERT_TRUE(s.final_error && s.map);
  EXPECT_NEAR(s.final_error->x_m, 0.01, 1e-9);
  EXPECT_GT(s.map->coverage, 0.99);
  EXPECT_GT(s.map->precision, 0.95);
  EXPECT_EQ(s.total, 300);
  EXPECT_EQ(s.max_total, 300);

  Referee late({CompetitionEvent::kSpeedRun, 120.0, 0.5}, world, 1);
  late.Tick(0);
  EXPECT_FALSE(late.StopReason(119'000'000));
  EXPECT_TRUE(late.StopReason(120'000'000));
  EXPECT_TRUE(late.Judge().timed_out);
}

// Each collision is kept with its time since the start, the true pose and SLAM's last estimate
// before it, taken from the map frame (the start) into the world, and scored against the truth at
// the estimate's own time (the robot drove on before it touched).
TEST(RefereeCollisions, EachIsKeptWithItsTimePoseAndTheEstimateThen) {
  const World world = World::Load(std::string(MBOT_SOURCE_DIR) + "/datasets/arenas/convex_circuit.arena");
  Referee r({CompetitionEvent::kMazeExplorer, 120.0, 0.5}, world, 1);
  const Pose2D start{1.0, 0.5, M_PI / 2};
  r.Tick(1'000'000);
  r.OnTruePose(1'000'000, start);
  r.Tick(2'000'000);
  r.OnCollision(2'000'000, {1.0, 0.4, M_PI});  // before SLAM published: no estimate
  r.OnTruePose(2'400'000, {1.0, 0.82, M_PI / 2});
  r.OnTruePose(2'600'000, {1.0, 0.84, M_PI / 2});  // the truth at 2.5 s: (1, 0.83)
  r.OnSlamPose(2'500'000, {0.3, 0.0, 0.0});        // 0.3 m ahead of the start, in the start's frame
  r.Tick(3'000'000);
  r.OnTruePose(3'000'000, {1.0, 0.9, M_PI / 2});
  r.OnCollision(3'000'000, {1.0, 0.9, M_PI / 2});
  const Score s = r.Judge();
  EXPECT_EQ(s.collisions, 2);
  ASSERT_EQ(s.collision_events.size(), 2u);
  EXPECT_DOUBLE_EQ(s.collision_events[0].t_s, 1.0);
  EXPECT_DOUBLE_EQ(s.collision_events[0].pose.theta, M_PI);
  EXPECT_FALSE(s.collision_events[0].estimate);
  EXPECT_TRUE(std::isnan(s.collision_events[0].estimate_error_m));
  EXPECT_DOUBLE_EQ(s.collision_events[1].t_s, 2.0);
  ASSERT_TRUE(s.collision_events[1].estimate);
  EXPECT_NEAR(s.collision_events[1].estimate->x, 1.0, 1e-12);  // ahead of the start is +y in the world
  EXPECT_NEAR(s.collision_events[1].estimate->y, 0.8, 1e-12);
  EXPECT_DOUBLE_EQ(s.collision_events[1].estimate_age_s, 0.5);
  EXPECT_NEAR(s.collision_events[1].estimate_error_m, 0.03, 1e-9);  // not 0.1, the distance to the collision
}

}  // namespace
}  // namespace mbot::sim
