// Each mission task on a kinematic robot (libs/mission alone: no pipeline, no simulator): the
// robot moves exactly as commanded, odometry is its true pose, SLAM reports the true pose at 10 Hz.
#include "mbot/mission/mission.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "mbot/common/config.hpp"
#include "mbot/mission/mission_config.hpp"
#include "mbot/mission/warehouse_rules.hpp"

namespace mbot::mission {
namespace {

using motion::Pose2D;

// A room of `w` × `h` metres with its lower-left corner at (x0, y0), walls one cell thick.
mapping::OccupancyGrid Room(double x0, double y0, double w, double h, double res = 0.05) {
  const int nx = static_cast<int>(std::lround(w / res)), ny = static_cast<int>(std::lround(h / res));
  mapping::OccupancyGrid g(nx, ny, res, x0, y0);
  for (int y = 0; y < ny; ++y) {
    for (int x = 0; x < nx; ++x) g.at(x, y) = (x == 0 || y == 0 || x == nx - 1 || y == ny - 1) ? 127 : -127;
  }
  return g;
}

MissionOptions Parse(const std::string& ini) {
  auto c = config::Config::FromString("[mission]\n" + ini);
  config::Section s = c.GetSection("mission");
  MissionOptions o = ParseMissionOptions(s);
  s.Finish();
  return o;
}

// Drives a Mission with a kinematic robot. `stuck` freezes the robot (a wall it pushes against);
// `reveal`, when set, is called with the true pose every SLAM update to produce the map.
struct KinematicRun {
  KinematicRun(Mission& m, const Pose2D& start) : mission(m), truth(start) {}
  Mission& mission;
  Pose2D truth;
  int64_t t_us = 0;
  bool stuck = false;
  std::vector<MissionStatus> statuses;
  std::vector<std::vector<Pose2D>> paths;
  std::vector<motion::VelocityCommand> commands;
  std::vector<ExplorationOut> seen;  // explore: what the explorer saw at each step
  std::function<std::shared_ptr<const mapping::OccupancyGrid>(const Pose2D&)> reveal;

  // Runs until the mission completes or fails, or `seconds` pass; returns the final state.
  MissionState Run(double seconds) {
    const int64_t end = t_us + static_cast<int64_t>(seconds * 1e6);
    for (; t_us < end; t_us += 20'000) {
      if (t_us % 100'000 == 0) {
        mission.OnPoseEstimate(t_us, truth);
        if (reveal) mission.OnMap(reveal(truth));
      }
      for (const MissionOutput& out : mission.OnOdometry(t_us, truth)) {
        if (const auto* s = std::get_if<MissionStatus>(&out)) statuses.push_back(*s);
        if (const auto* p = std::get_if<PathOut>(&out)) paths.push_back(p->poses);
        if (const auto* x = std::get_if<ExplorationOut>(&out)) seen.push_back(*x);
        if (const auto* c = std::get_if<motion::VelocityCommand>(&out)) {
          commands.push_back(*c);
          if (!stuck) truth = motion::StepUnicycle(truth, *c, 0.02);
        }
      }
      if (IsFinal(mission.status().state)) break;
    }
    return mission.status().state;
  }
  bool Saw(MissionState s) const {
    for (const MissionStatus& st : statuses) {
      if (st.state == s) return true;
    }
    return false;
  }
};

TEST(MissionWaypoints, DrivesTheCircuitAndStopsAtTheLastWaypoint) {
  Mission m(Parse("task = waypoints\nwaypoints = 1, 0, 90; 1, 1, 180; 0, 1, -90\n"), 1);
  KinematicRun run(m, {0, 0, 0});
  EXPECT_EQ(run.Run(60), MissionState::kCompleted) << m.status().detail;
  EXPECT_TRUE(run.Saw(MissionState::kInitializing));
  EXPECT_TRUE(run.Saw(MissionState::kDriving));
  EXPECT_NEAR(run.truth.x, 0.0, 0.03);
  EXPECT_NEAR(run.truth.y, 1.0, 0.03);
  EXPECT_NEAR(motion::WrapAngle(run.truth.theta + M_PI / 2), 0.0, 0.06);
  ASSERT_FALSE(run.paths.empty());
  EXPECT_EQ(run.paths.front().size(), 3u);  // the circuit is published as the first path
  // Every step ends with one command.
  EXPECT_GT(run.commands.size(), 100u);
}

TEST(MissionWaypoints, ACircuitWithoutWaypointsIsAConfigurationError) {
  EXPECT_THROW(Parse("task = waypoints\n"), config::ConfigError);
  EXPECT_THROW(Parse("task = waypoints\nwaypoints = 1, 0\n"), config::ConfigError);
}

// A 4 m × 2 m room of which the robot knows only what lies within 1.2 m of where it has been: it
// explores until no frontier is left and returns home.
TEST(MissionExplore, ExploresTheRoomAndReturnsHome) {
  const mapping::OccupancyGrid truth = Room(-0.5, -0.5, 4.0, 2.0);
  auto known = std::make_shared<mapping::OccupancyGrid>(truth);
  std::fill(known->cells().begin(), known->cells().end(), 0);
  Mission m(Parse("task = explore\nrobot_radius_m = 0.1\n"), 1);
  m.set_watched(true);
  KinematicRun run(m, {0, 0, 0});
  run.reveal = [&](const Pose2D& p) {
    for (int y = 0; y < truth.height(); ++y) {
      for (int x = 0; x < truth.width(); ++x) {
        double cx, cy;
        truth.CellToWorld(x, y, &cx, &cy);
        if (std::hypot(cx - p.x, cy - p.y) <= 1.2) known->at(x, y) = truth.at(x, y);
      }
    }
    return std::make_shared<const mapping::OccupancyGrid>(*known);
  };
  EXPECT_EQ(run.Run(300), MissionState::kCompleted) << m.status().detail;
  EXPECT_TRUE(run.Saw(MissionState::kExploring));
  EXPECT_TRUE(run.Saw(MissionState::kReturningHome));
  EXPECT_LT(std::hypot(run.truth.x, run.truth.y), 0.03);
  int unknown_inside = 0;
  for (int y = 1; y + 1 < truth.height(); ++y) {
    for (int x = 1; x + 1 < truth.width(); ++x) unknown_inside += known->at(x, y) == 0;
  }
  EXPECT_EQ(unknown_inside, 0) << "the robot came home before it had seen the whole room";
  // For a viewer: the explorer's frontiers (there were some at the start, none at the end) and its
  // distances, on the map's grid, 0 at the walls.
  ASSERT_GT(run.seen.size(), 10u);
  EXPECT_FALSE(run.seen.front().frontiers.regions.empty());
  EXPECT_FALSE(run.seen.front().frontiers.regions.front().cells.empty());
  EXPECT_TRUE(run.seen.back().frontiers.regions.empty());
  ASSERT_TRUE(run.seen.back().distances);
  const msgs::DistanceGrid& d = *run.seen.back().distances;
  EXPECT_EQ(d.width, truth.width());
  EXPECT_EQ(d.height, truth.height());
  EXPECT_EQ(d.distance_m[0], 0.0f);                                    // a wall cell
  EXPECT_NEAR(d.distance_m[size_t(20) * d.width + 40], 0.95f, 0.05f);  // the room's middle row: 19 cells to the wall
  if (unknown_inside) {
    for (int y = truth.height() - 1; y >= 0; y -= 2) {
      std::string row;
      for (int x = 0; x < truth.width(); x += 2) row += known->at(x, y) > 0 ? '#' : known->at(x, y) < 0 ? '.' : '?';
      std::printf("%s\n", row.c_str());
    }
  }
}

// The Warehouse in a 4 m × 3 m room: nothing moves until SLAM says localized; then every stop in
// the seed's order, standing dwell_s at each.
TEST(MissionWarehouse, WaitsForLocalizationThenVisitsEveryStopInOrder) {
  const std::string ini =
      "task = warehouse\nrobot_radius_m = 0.1\ndwell_s = 0.5\n"
      "targets = 0.5, 0.5, 0; 1.5, 0.5, 90; 2.5, 0.5, 0; 3.2, 1.0, 90; 2.5, 2.2, 180; 1.5, 2.2, -90; 0.5, 2.2, 180\n"
      "dropoffs = 0.5, 1.35, 180\n";
  const MissionOptions o = Parse(ini);
  Mission m(o, 4);
  m.OnMap(std::make_shared<const mapping::OccupancyGrid>(Room(-0.2, -0.2, 4.0, 3.0)));
  m.OnSlamState(mapping::SlamState::kLocalizing);
  KinematicRun run(m, {1.8, 1.35, 0});
  run.Run(3);
  EXPECT_EQ(m.status().state, MissionState::kLocalizing);
  for (const auto& c : run.commands) ASSERT_EQ(c.v_m_s, 0.0);
  m.OnSlamState(mapping::SlamState::kLocalized);
  EXPECT_EQ(run.Run(600), MissionState::kCompleted) << m.status().detail;
  const auto stops = warehouse::Stops(o.targets, o.dropoffs, 4);
  int lifts = 0, set_downs = 0;
  for (const MissionStatus& s : run.statuses)
    lifts += s.state == MissionState::kLifting, set_downs += s.state == MissionState::kSettingDown;
  EXPECT_EQ(lifts, 7);
  EXPECT_EQ(set_downs, 7);
  EXPECT_EQ(m.Report().stops_done, 14);
  EXPECT_TRUE(warehouse::AtStop(run.truth, stops.back().pose));
}

TEST(MissionWarehouse, TooFewTargetsIsAConfigurationErrorNamingTheKey) {
  try {
    Parse("task = warehouse\ntargets = 1, 1, 0\ndropoffs = 0, 0, 0\n");
    ADD_FAILURE();
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("targets"), std::string::npos) << e.what();
  }
}

TEST(MissionFollow, DrivesEachPathItIsSentAndDoesNotPublishItBack) {
  Mission m(Parse("task = follow\nstart_delay_s = 0\n"), 1);
  KinematicRun run(m, {0, 0, 0});
  run.Run(1);
  EXPECT_EQ(m.status().state, MissionState::kWaiting);
  m.OnPath({{0.5, 0, 0}, {0.5, 0.5, M_PI / 2}});
  run.Run(30);
  EXPECT_EQ(m.status().state, MissionState::kArrived);
  EXPECT_NEAR(run.truth.x, 0.5, 0.03);
  EXPECT_NEAR(run.truth.y, 0.5, 0.03);
  EXPECT_TRUE(run.paths.empty());
}

// A person at the viewer: a goal is planned with A* on the map and driven to; teleop drives only
// while its commands keep coming (the dead man: teleop_timeout_s), clamped to the controller's
// limits; either takes over from the task.
TEST(MissionPerson, DrivesToAPersonsGoalThenObeysTeleopUntilItStops) {
  auto room = std::make_shared<const mapping::OccupancyGrid>(Room(-1, -1, 3, 3));
  Mission m(Parse("task = explore\nstart_delay_s = 0\nrobot_radius_m = 0.1\n"), 1);
  KinematicRun run(m, {0, 0, 0});
  run.reveal = [&](const Pose2D&) { return room; };
  run.Run(0.5);
  m.OnGoal({1.0, 0.8, 0});
  run.Run(30);
  EXPECT_TRUE(m.manual());
  EXPECT_EQ(m.status().state, MissionState::kArrived) << m.status().detail;
  EXPECT_NEAR(run.truth.x, 1.0, 0.03);
  EXPECT_NEAR(run.truth.y, 0.8, 0.03);
  // Teleop at 5 m/s asks too much: clamped to the controller's 0.3 m/s; after its last command
  // the robot stops within the dead man's 0.5 s.
  run.commands.clear();
  m.OnTeleop(run.t_us, 5.0, 0.0);
  run.Run(0.3);
  ASSERT_FALSE(run.commands.empty());
  EXPECT_NEAR(run.commands.back().v_m_s, 0.3, 1e-9);
  run.Run(0.4);  // 0.7 s after the only teleop command
  EXPECT_EQ(run.commands.back().v_m_s, 0.0);
  EXPECT_EQ(m.status().state, MissionState::kWaiting) << m.status().detail;
}

// Pushing against something: the robot backs off after stuck_s, and after max_stalls stalls on
// the way to one goal the mission fails and stops.
TEST(MissionRecovery, BacksOffWhenStalledAndGivesUpAfterMaxStalls) {
  Mission m(Parse("task = waypoints\nwaypoints = 2, 0, 0\nmax_stalls = 2\nstuck_s = 0.5\n"), 1);
  KinematicRun run(m, {0, 0, 0});
  run.stuck = true;
  EXPECT_EQ(run.Run(30), MissionState::kFailed);
  EXPECT_NE(m.status().detail.find("stalled 3 times"), std::string::npos) << m.status().detail;
  EXPECT_EQ(m.Report().stall_recoveries, 2);
  int reversing = 0;
  for (const auto& c : run.commands) reversing += c.v_m_s < 0;
  EXPECT_GT(reversing, 10);
}

// A stall while driving marks what the robot ran into on the map it plans on, ahead of it: against
// the free end of a wall the map's end is short of the real one, and the next plan must not graze
// it again.
TEST(MissionRecovery, AStallMarksAnObstacleAheadOnTheMapItPlansOn) {
  auto room = std::make_shared<const mapping::OccupancyGrid>(Room(-1, -1, 3, 3));
  Mission m(Parse("task = explore\nstart_delay_s = 0\nrobot_radius_m = 0.1\nstuck_s = 0.5\n"), 1);
  KinematicRun run(m, {0, 0, 0});
  run.reveal = [&](const Pose2D&) { return room; };
  run.Run(0.5);
  m.OnGoal({1.5, 0.0, 0});
  run.Run(1.0);
  run.stuck = true;
  run.Run(1.0);
  ASSERT_GE(m.Report().bumps, 1);
  ASSERT_TRUE(m.map());
  int cx = 0, cy = 0;
  m.map()->WorldToCell(run.truth.x + 0.12, run.truth.y, &cx, &cy);
  EXPECT_EQ(m.map()->at(cx, cy), 127);
  EXPECT_EQ(room->at(cx, cy) == 127, false);  // SLAM's own map is not changed
}

TEST(MissionState, NamesRoundTrip) {
  for (MissionState s : {MissionState::kInitializing, MissionState::kReturningHome, MissionState::kSettingDown,
                         MissionState::kCompleted, MissionState::kFailed}) {
    EXPECT_EQ(MissionStateFromString(ToString(s)), s);
  }
  EXPECT_FALSE(MissionStateFromString("returning home").has_value());
}

}  // namespace
}  // namespace mbot::mission
