// The Heavy Lift task phase by phase on a kinematic robot (libs/mission alone): the robot moves
// exactly as commanded, SLAM reports the true pose, a camera sees the tag on the crate face turned
// towards it (within 1.5 m and 30 degrees of the heading), and a forklift's tines follow their
// command at 0.1 m/s and catch a crate when lifted with their tips inside its footprint.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>

#include "heavy_lift/heavy_lift_task.hpp"
#include "mbot/common/config.hpp"
#include "mbot/mission/mission.hpp"
#include "mbot/mission/mission_config.hpp"

namespace mbot::mission {
namespace {

using motion::Pose2D;

constexpr double kSide = 0.10, kTip = 0.18;  // the defaults: crate side, tines' tips ahead of the centre

struct FakeCrate {
  int id;
  Pose2D pose;
};

// A 4 m × 4 m room round the start, its crates drawn in the map as SLAM would have them.
std::shared_ptr<const mapping::OccupancyGrid> RoomWith(const std::vector<FakeCrate>& crates) {
  const double res = 0.05;
  auto g = std::make_shared<mapping::OccupancyGrid>(80, 80, res, -1.5, -2.0);
  for (int y = 0; y < 80; ++y) {
    for (int x = 0; x < 80; ++x) g->at(x, y) = (x == 0 || y == 0 || x == 79 || y == 79) ? 127 : -127;
  }
  for (const FakeCrate& c : crates) {
    int cx, cy;
    g->WorldToCell(c.pose.x, c.pose.y, &cx, &cy);
    for (int dy = -1; dy <= 0; ++dy) {
      for (int dx = -1; dx <= 0; ++dx) g->at(cx + dx, cy + dy) = 127;
    }
  }
  return g;
}

struct HeavyLiftRun {
  explicit HeavyLiftRun(const std::string& stack, std::vector<FakeCrate> c) : crates(std::move(c)) {
    auto cfg = config::Config::FromString("[mission]\ntask = heavy_lift\nstack = " + stack + "\n");
    config::Section s = cfg.GetSection("mission");
    mission = std::make_unique<Mission>(ParseMissionOptions(s), 1);
    map = RoomWith(crates);
  }

  std::unique_ptr<Mission> mission;
  std::vector<FakeCrate> crates;
  std::shared_ptr<const mapping::OccupancyGrid> map;
  Pose2D truth;
  int64_t t_us = 0;
  bool catches = true;  // false: the tines always miss the slot
  ForkliftState fork;
  double fork_target = 0;
  int carried = -1;
  Pose2D carried_offset;  // the carried crate in the robot's frame
  std::vector<MissionStatus> statuses;
  std::vector<motion::VelocityCommand> commands;
  std::vector<double> fork_commands;
  std::optional<Pose2D> pose_at_first_lift;  // the robot when the tines were first commanded up

  FakeCrate& Crate(int id) {
    for (FakeCrate& c : crates) {
      if (c.id == id) return c;
    }
    throw std::logic_error("no crate " + std::to_string(id));
  }

  // The tags the camera sees now: the face of each crate turned towards the robot.
  std::vector<TagSeen> Camera() const {
    std::vector<TagSeen> seen;
    for (const FakeCrate& c : crates) {
      if (c.id == carried) continue;
      const double bearing = std::atan2(truth.y - c.pose.y, truth.x - c.pose.x);
      const double q = 0.5 * M_PI;
      const double normal = c.pose.theta + q * std::round(motion::WrapAngle(bearing - c.pose.theta) / q);
      const Pose2D tag{c.pose.x + 0.5 * kSide * std::cos(normal), c.pose.y + 0.5 * kSide * std::sin(normal), normal};
      const Pose2D in_robot = truth.Inverse().Compose(tag);
      const double range = std::hypot(in_robot.x, in_robot.y);
      if (range > 1.5 || in_robot.x <= 0 || std::abs(std::atan2(in_robot.y, in_robot.x)) > 30 * M_PI / 180) continue;
      seen.push_back({c.id, in_robot.x, in_robot.y, 0.0, in_robot.theta});
    }
    return seen;
  }

  void Forklift(double dt) {
    const double step = 0.1 * dt;
    fork.height_m += std::clamp(fork_target - fork.height_m, -step, step);
    fork.target_m = fork_target;
    if (carried < 0 && fork.height_m > 0.01 && catches) {
      const Pose2D tip = truth.Compose({kTip, 0, 0});
      for (const FakeCrate& c : crates) {
        const Pose2D in_crate = c.pose.Inverse().Compose(tip);
        if (std::abs(in_crate.x) < 0.5 * kSide && std::abs(in_crate.y) < 0.5 * kSide) {
          carried = c.id;
          carried_offset = truth.Inverse().Compose(c.pose);
        }
      }
    }
    if (carried >= 0 && fork_target == 0 && fork.height_m < 0.002) carried = -1;  // set down where it is
    if (carried >= 0) Crate(carried).pose = truth.Compose(carried_offset);
    fork.crate_id = carried;
    fork.carrying = carried >= 0;
  }

  MissionState Run(double seconds) {
    const int64_t end = t_us + static_cast<int64_t>(seconds * 1e6);
    mission->OnSlamState(mapping::SlamState::kMapping);
    for (; t_us < end; t_us += 20'000) {
      if (t_us % 100'000 == 0) {
        mission->OnPoseEstimate(t_us, truth);
        mission->OnMap(map);
        mission->OnTags(t_us, Camera());
        mission->OnForklift(fork);
      }
      for (const MissionOutput& out : mission->OnOdometry(t_us, truth)) {
        if (const auto* s = std::get_if<MissionStatus>(&out)) statuses.push_back(*s);
        if (const auto* f = std::get_if<ForkOut>(&out)) {
          fork_commands.push_back(f->height_m);
          if (f->height_m > 0 && !pose_at_first_lift) pose_at_first_lift = truth;
          fork_target = f->height_m;
        }
        if (const auto* c = std::get_if<motion::VelocityCommand>(&out)) {
          commands.push_back(*c);
          truth = motion::StepUnicycle(truth, *c, 0.02);
        }
      }
      Forklift(0.02);
      if (IsFinal(mission->status().state)) break;
    }
    return mission->status().state;
  }

  bool Said(const std::string& detail) const {
    for (const MissionStatus& s : statuses) {
      if (s.detail.find(detail) != std::string::npos) return true;
    }
    return false;
  }
};

// --- the crate estimate (heavy_lift/heavy_lift_task.hpp) ---

TEST(HeavyLiftCrateEstimate, NearerSightingsWeighMoreAndTheHeadingIsModuloAQuarterTurn) {
  heavy_lift::CrateEstimate e;
  EXPECT_FALSE(e.known());
  e.Add(1.00, 0.0, 0.02 + 0.5 * M_PI, 0.3, 0);  // seen from the side: the same crate a quarter turn on
  e.Add(1.10, 0.0, -0.02, 1.5, 1);              // far: 25 times less weight
  const Pose2D c = e.Get();
  EXPECT_NEAR(c.x, 1.0 + 0.1 / 26, 1e-9);
  EXPECT_NEAR(c.theta, 0.02 * 24 / 26, 2e-3);
  EXPECT_EQ(e.SeenSince(1), 1);
  e.ForgetBefore(1);
  EXPECT_NEAR(e.Get().x, 1.10, 1e-12);
  for (int k = 0; k < 20; ++k) e.Add(2.0, 0.0, 0.0, 1.0, 10 + k);  // only the last 15 count
  EXPECT_NEAR(e.Get().x, 2.0, 1e-12);
}

// --- the phases, on the kinematic robot ---

// Survey: before anything else, one whole turn on the spot at search_turn_rad_s.
TEST(HeavyLiftPhases, SurveyTurnsOnceOnTheSpotFirst) {
  HeavyLiftRun run("1:11", {{1, {1.0, 0.0, 0.0}}, {11, {1.0, 1.0, 0.0}}});
  run.Run(15.0);
  double turned = 0;
  size_t k = 0;
  for (; k < run.commands.size() && run.commands[k].v_m_s == 0.0; ++k) turned += run.commands[k].w_rad_s * 0.02;
  EXPECT_GE(turned, 2 * M_PI - 0.05);
  EXPECT_LE(turned, 2 * M_PI + 0.1);
  EXPECT_TRUE(run.Said("one turn on the spot"));
}

// Find and approach: to the stand-off square to the face towards the robot, then the tines in along
// its normal, their tips insert_depth (0.04 m) past the face when they are lifted.
TEST(HeavyLiftPhases, TheTinesGoInSquareToTheFaceTowardsTheRobot) {
  HeavyLiftRun run("1:11", {{1, {1.0, 0.0, 0.0}}, {11, {1.0, 1.0, 0.0}}});
  run.Run(60.0);
  EXPECT_TRUE(run.Said("to crate 1"));
  ASSERT_TRUE(run.pose_at_first_lift.has_value());
  const Pose2D p = *run.pose_at_first_lift;
  EXPECT_NEAR(p.x + kTip, 1.0 - 0.5 * kSide + 0.04, 0.01);  // the tips 4 cm past the face at x = 0.95
  EXPECT_NEAR(p.y, 0.0, 0.015);                             // on the face's normal
  EXPECT_NEAR(motion::WrapAngle(p.theta), 0.0, 5 * M_PI / 180);
}

// Lift and place: the crate on the tines, back off, to the other crate with the tines at the
// stacking height, the carried crate over it, down, back off, home.
TEST(HeavyLiftPhases, LiftedBackedOffCarriedOverTheOtherSetDownAndHome) {
  HeavyLiftRun run("1:11", {{1, {1.0, 0.0, 0.0}}, {11, {1.0, 1.0, 0.0}}});
  EXPECT_EQ(run.Run(240.0), MissionState::kCompleted) << run.mission->status().detail;
  EXPECT_TRUE(run.Said("lifted 1: backing off"));
  EXPECT_TRUE(run.Said("carrying crate 1 onto crate 11"));
  EXPECT_TRUE(run.Said("set down: backing off"));
  EXPECT_TRUE(run.Said("1 of 1 crates set down"));
  // The stacking height was commanded before the set-down.
  bool stacking = false;
  for (double h : run.fork_commands) stacking |= std::abs(h - 0.13) < 1e-9;
  EXPECT_TRUE(stacking);
  // Crate 1 ends over crate 11, and the robot home.
  const Pose2D c1 = run.Crate(1).pose, c11 = run.Crate(11).pose;
  EXPECT_LT(std::hypot(c1.x - c11.x, c1.y - c11.y), 0.03);
  EXPECT_LT(std::hypot(run.truth.x, run.truth.y), 0.1);
  const MissionReport r = run.mission->Report();
  EXPECT_EQ(r.crates_lifted, 1);
  EXPECT_EQ(r.crates_set_down, 1);
}

// A missed slot: tines up without the crate, down, back off, try again; given up after
// max_attempts (3).
TEST(HeavyLiftPhases, AMissedLiftIsTriedAgainThenGivenUp) {
  HeavyLiftRun run("1:11", {{1, {1.0, 0.0, 0.0}}, {11, {1.0, 1.0, 0.0}}});
  run.catches = false;
  EXPECT_EQ(run.Run(240.0), MissionState::kFailed);
  EXPECT_TRUE(run.Said("missed crate 1; backing off to try again"));
  EXPECT_NE(run.mission->status().detail.find("could not engage crate 1 in 3 tries"), std::string::npos)
      << run.mission->status().detail;
}

// A crate the robot cannot see from the start is looked for from round the crates it saw.
TEST(HeavyLiftPhases, ACrateNotSeenIsLookedForFromAnotherSide) {
  // Crate 2 hides behind crate 1 from the start (and is out of the camera's range).
  HeavyLiftRun run("2:11", {{1, {1.0, 0.0, 0.0}}, {2, {1.6, 0.0, 0.0}}, {11, {1.0, 1.0, 0.0}}});
  run.Run(120.0);
  EXPECT_TRUE(run.Said("looking for crate 2 from another side of the crates")) << run.mission->status().detail;
}

}  // namespace
}  // namespace mbot::mission
