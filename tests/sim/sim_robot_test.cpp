#include "mbot/sim/sim_robot.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <sstream>
#include <type_traits>
#include <variant>

#include "mbot/common/config.hpp"
#include "mbot/drivers/source_options.hpp"
#include "mbot/sim/sim_source.hpp"
#include "../drivers/test_util.hpp"

namespace mbot::sim {
namespace {

using namespace mbot::msgs;  // the event and source types the simulator speaks

using motion::Pose2D;

constexpr int64_t kSecond = 1000000;

World Box(double half) {
  std::ostringstream a;
  a << "name box\nbox " << -half << " " << -half << " " << half << " " << half << "\n";
  return World::ParseArena(a.str(), "box.arena");
}

// Commands (v, w) every 0.1 s until `until_s`, as a controller does (the firmware stops the motors
// after 1 s without a command).
std::vector<Event> Drive(SimRobot& robot, double v, double w, double until_s) {
  std::vector<Event> out;
  const int64_t until = static_cast<int64_t>(until_s * kSecond);
  while (robot.now_us() < until) {
    robot.Command(v, w);
    robot.AdvanceTo(std::min(until, robot.now_us() + kSecond / 10), &out);
  }
  return out;
}

std::vector<Event> OfKind(const std::vector<Event>& events, EventKind kind) {
  std::vector<Event> out;
  for (const auto& e : events) {
    if (e.kind == kind) out.push_back(e);
  }
  return out;
}

const Pose2D& PoseOf(const Event& e) { return std::get<Pose2D>(e.payload); }

// The ground-truth pose at t_us (the series holds one every 10 ms).
Pose2D TruthAt(const std::vector<Event>& events, int64_t t_us) {
  std::vector<motion::TimedPose> series;
  for (const auto& e : OfKind(events, EventKind::kGroundTruth)) series.push_back({e.t_us, PoseOf(e)});
  Pose2D p;
  EXPECT_TRUE(motion::InterpolateAt(series, t_us, 20000, &p)) << t_us;
  return p;
}

TEST(SimRobot, DrivesStraightAtTheCommandedSpeed) {
  World world = Box(3.0);
  const Pose2D start{-1.5, 0.2, 0.1};
  // Motors as the firmware's calibration believes them (the fitted default runs its wheels 12 %
  // faster than that, which its speed loop makes up only in part).
  SimRobotOptions o;
  o.left_motor_gain = o.right_motor_gain = 1.0;
  SimRobot robot(world, o, start, 1);
  const auto events = Drive(robot, 0.2, 0.0, 5.0);
  // Steady state (the command and PWM filters settle within ~1 s): speed within 3 %.
  const Pose2D a = TruthAt(events, 2 * kSecond), b = TruthAt(events, 5 * kSecond);
  EXPECT_NEAR(std::hypot(b.x - a.x, b.y - a.y) / 3.0, 0.2, 0.2 * 0.03);
  // The whole run: 1 m less the start-up lag (about 0.25 s of the filters' time constants).
  EXPECT_GT(robot.distance_travelled_m(), 0.9);
  EXPECT_LT(robot.distance_travelled_m(), 1.0);
  // The firmware's odometry (from the start, in its own frame) agrees with the truth within a few cm.
  const Pose2D odo = PoseOf(OfKind(events, EventKind::kOdometry).back());
  const Pose2D truth = start.Inverse().Compose(robot.true_pose());
  EXPECT_LT(std::hypot(odo.x - truth.x, odo.y - truth.y), 0.03);
  EXPECT_LT(std::abs(motion::WrapAngle(odo.theta - truth.theta)), 0.05);
  EXPECT_EQ(robot.collisions(), 0);
}

// The firmware's gate on a faulty bus: a command beyond twice its limits (a corrupt one: 1e5 m/s) is
// refused and the last good command holds; up to twice them it is clamped, as the firmware does;
// a non-finite one stops the robot.
TEST(SimRobot, RefusesCommandsFarBeyondTheFirmwaresLimits) {
  World world = Box(3.0);
  SimRobot robot(world, SimRobotOptions{}, {-1.5, 0, 0}, 1);
  std::vector<Event> out;
  EXPECT_TRUE(robot.Command(0.2, 0.0));
  robot.AdvanceTo(kSecond, &out);
  EXPECT_FALSE(robot.Command(1e5, 0.0));
  EXPECT_FALSE(robot.Command(-1.7, 0.0));  // MAX_FWD_VEL 0.8 m/s, twice it 1.6
  EXPECT_FALSE(robot.Command(0.2, 5.1));   // MAX_TURN_VEL 2.5 rad/s
  EXPECT_TRUE(robot.Command(0.2, 0.0));
  robot.AdvanceTo(2 * kSecond, &out);
  EXPECT_EQ(robot.commands_refused(), 3);
  // Driven at 0.2 m/s throughout: the refused commands changed nothing.
  EXPECT_GT(robot.distance_travelled_m(), 0.3);
  EXPECT_LT(robot.distance_travelled_m(), 0.42);
  // 1.2 m/s is clamped to 0.8: over a second at most 0.8 m more.
  const double before = robot.distance_travelled_m();
  for (int k = 0; k < 10; ++k) {
    EXPECT_TRUE(robot.Command(1.2, 0.0));
    robot.AdvanceTo(robot.now_us() + kSecond / 10, &out);
  }
  EXPECT_LT(robot.distance_travelled_m() - before, 0.8 + 1e-6);
  EXPECT_GT(robot.distance_travelled_m() - before, 0.4);
  // NaN: the robot stops.
  EXPECT_FALSE(robot.Command(NAN, 0.0));
  robot.AdvanceTo(robot.now_us() + kSecond, &out);
  const double stopped = robot.distance_travelled_m();
  robot.AdvanceTo(robot.now_us() + kSecond / 2, &out);
  EXPECT_NEAR(robot.distance_travelled_m(), stopped, 1e-3);
}

TEST(SimRobot, TurnsInPlace) {
  World world = Box(2.0);
  SimRobot robot(world, SimRobotOptions{}, {0, 0, 0}, 2);
  const auto events = Drive(robot, 0.0, 1.0, 4.0);
  // Unwrapped true heading from the 100 Hz ground truth; steady yaw rate within 5 % of 1 rad/s.
  const auto truth = OfKind(events, EventKind::kGroundTruth);
  double heading = 0.0, at2 = 0.0;
  for (size_t i = 1; i < truth.size(); ++i) {
    heading += motion::WrapAngle(PoseOf(truth[i]).theta - PoseOf(truth[i - 1]).theta);
    if (truth[i].t_us == 2 * kSecond) at2 = heading;
  }
  EXPECT_NEAR((heading - at2) / 2.0, 1.0, 0.05);
  EXPECT_GT(heading, 3.5);
  EXPECT_LT(heading, 4.0);
  // The robot stays on the spot (slip moves it a little).
  EXPECT_LT(std::hypot(robot.true_pose().x, robot.true_pose().y), 0.03);
  // The firmware's gyro-fused heading is sane.
  const Pose2D odo = PoseOf(OfKind(events, EventKind::kOdometry).back());
  EXPECT_LT(std::abs(motion::WrapAngle(odo.theta - robot.true_pose().theta)), 0.1);
  // The gyro sees the turn (rate + bias + noise).
  const auto imu = OfKind(events, EventKind::kImu);
  ASSERT_EQ(imu.size(), 200u);  // 50 Hz
  EXPECT_NEAR(std::get<Imu>(imu.back().payload).gyro_rad_s[2], 1.0, 0.1);
}

TEST(SimRobot, EncoderTicksFollowTheWheelRotation) {
  World world = Box(3.0);
  SimRobotOptions o;
  o.slip_stddev = 0.0;  // ground motion = rotation · r
  SimRobot robot(world, o, {-1.5, 0, 0}, 3);
  const auto events = Drive(robot, 0.25, 0.3, 3.0);
  const auto enc = OfKind(events, EventKind::kEncoders);
  const auto speeds = OfKind(events, EventKind::kWheelSpeed);
  ASSERT_EQ(enc.size(), 150u);  // 50 Hz
  ASSERT_EQ(speeds.size(), enc.size());
  const double rad_per_tick = o.geometry.RadPerTick();
  int64_t left = 0, right = 0;
  for (size_t i = 0; i < enc.size(); ++i) {
    const auto& e = std::get<EncoderTicks>(enc[i].payload);
    left += e.left_delta;
    right += e.right_delta;
    EXPECT_EQ(e.left_ticks, left);
    EXPECT_EQ(e.right_ticks, right);
    EXPECT_EQ(e.delta_time_us, 20000);
    const auto& s = std::get<WheelSpeeds>(speeds[i].payload);
    EXPECT_DOUBLE_EQ(s.left_rad_s, e.left_delta * rad_per_tick / 0.02);
    EXPECT_DOUBLE_EQ(s.right_rad_s, e.right_delta * rad_per_tick / 0.02);
  }
  // Distance and turn from the ticks match the truth (within a tick or two of quantisation).
  const double m_per_tick = rad_per_tick * o.geometry.wheel_radius_m;
  EXPECT_NEAR(0.5 * (left + right) * m_per_tick, robot.distance_travelled_m(), 2 * m_per_tick);
  EXPECT_NEAR((right - left) * m_per_tick / (2 * o.geometry.base_radius_m), robot.true_pose().theta, 0.01);
  EXPECT_GT(right, left);  // turning left
  EXPECT_EQ(robot.right_ticks(), right);

  // A mirrored right encoder counts down going forward; the firmware's odometry knows it.
  o.geometry.right_encoder_polarity = -1;
  SimRobot mirrored(world, o, {-1.5, 0, 0}, 3);
  const auto straight = Drive(mirrored, 0.2, 0.0, 2.0);
  EXPECT_LT(std::get<EncoderTicks>(OfKind(straight, EventKind::kEncoders).back().payload).right_ticks, -1000);
  EXPECT_GT(std::get<WheelSpeeds>(OfKind(straight, EventKind::kWheelSpeed).back().payload).right_rad_s, 4.0);
  const Pose2D odo = PoseOf(OfKind(straight, EventKind::kOdometry).back());
  EXPECT_NEAR(odo.x, mirrored.true_pose().x + 1.5, 0.01);
  EXPECT_NEAR(odo.y, mirrored.true_pose().y, 0.01);
}

TEST(SimRobot, LidarScanMatchesRaycastAtRest) {
  World world = Box(2.0);
  SimRobotOptions o;
  o.lidar.range_noise_m = 0.0;
  o.lidar.dropout = 0.0;
  o.lidar.max_range_m = 2.5;  // the corners (2.83 m away) give no return
  const Pose2D start{0.3, -0.2, 0.4};
  SimRobot robot(world, o, start, 4);
  const auto scans = OfKind(Drive(robot, 0, 0, 0.13), EventKind::kLidar);
  ASSERT_EQ(scans.size(), 1u);
  EXPECT_EQ(scans[0].t_us, 125000);
  const auto& scan = std::get<LidarScan>(scans[0].payload);
  ASSERT_EQ(scan.ranges_m.size(), 360u);
  ASSERT_EQ(scan.angles_rad.size(), 360u);
  ASSERT_EQ(scan.beam_times_us.size(), 360u);
  EXPECT_FLOAT_EQ(scan.max_range_m, 2.5f);
  EXPECT_EQ(scan.beam_times_us.front(), 0);
  EXPECT_GE(scan.beam_times_us.back(), 125000 * 359 / 360);
  EXPECT_LT(scan.beam_times_us.back(), 125000);
  int no_returns = 0;
  for (size_t i = 0; i < scan.ranges_m.size(); ++i) {
    if (i > 0) {
      EXPECT_GT(scan.beam_times_us[i], scan.beam_times_us[i - 1]);
      EXPECT_NEAR(motion::WrapAngle(scan.angles_rad[i] - scan.angles_rad[i - 1]), -2 * M_PI / 360, 1e-5);  // clockwise
    }
    const double expected = world.Raycast(start.x, start.y, start.theta + scan.angles_rad[i], 2.5);
    if (expected >= 2.5) {
      EXPECT_EQ(scan.ranges_m[i], 0.0f) << i;
      ++no_returns;
    } else {
      EXPECT_FLOAT_EQ(scan.ranges_m[i], static_cast<float>(expected)) << i;
    }
  }
  EXPECT_GT(no_returns, 0);
  EXPECT_LT(no_returns, 100);
}

TEST(SimRobot, LidarBeamsAreTakenAtTheirOwnTimesWhileMoving) {
  World world = Box(2.0);
  SimRobotOptions o;
  o.lidar.range_noise_m = 0.0;
  o.lidar.dropout = 0.0;
  o.ground_truth_rate_hz = 1000.0;  // fine truth to interpolate the beams' poses from
  SimRobot robot(world, o, {-0.5, 0.3, 0}, 5);
  const auto events = Drive(robot, 0.2, 1.5, 2.0);
  const auto scans = OfKind(events, EventKind::kLidar);
  ASSERT_EQ(scans.size(), 16u);
  const auto& scan = std::get<LidarScan>(scans.back().payload);  // turning at ~1.5 rad/s: 0.19 rad per revolution
  double worst = 0.0;
  for (size_t i = 0; i < scan.ranges_m.size(); i += 7) {
    const Pose2D p = TruthAt(events, scan.beam_times_us[i]);
    const double expected = world.Raycast(p.x, p.y, p.theta + scan.angles_rad[i], o.lidar.max_range_m);
    worst = std::max(worst, std::abs(scan.ranges_m[i] - expected));
  }
  EXPECT_LT(worst, 0.005);
}

TEST(SimRobot, StopsAtAWallAndCountsEachContactOnce) {
  World world = Box(1.0);
  SimRobotOptions o;
  SimRobot robot(world, o, {0, 0, 0}, 6);
  auto events = Drive(robot, 0.3, 0.0, 6.0);
  for (const auto& e : OfKind(events, EventKind::kGroundTruth)) {
    ASSERT_FALSE(world.Collides(PoseOf(e).x, PoseOf(e).y, o.footprint_radius_m)) << e.t_us;
  }
  EXPECT_EQ(robot.collisions(), 1);
  EXPECT_TRUE(robot.in_contact());
  const auto hits = OfKind(events, EventKind::kCollision);
  ASSERT_EQ(hits.size(), 1u);
  EXPECT_EQ(hits[0].channel, "SIM_COLLISION");
  // It stopped just short of the wall, and the wheels stall: the encoders stop counting.
  EXPECT_LT(world.ClearanceAt(robot.true_pose().x, robot.true_pose().y), o.footprint_radius_m + 0.005);
  EXPECT_GT(robot.true_pose().x, 0.85);
  const auto enc = OfKind(events, EventKind::kEncoders);
  const auto& at5 = std::get<EncoderTicks>(enc[enc.size() - 51].payload);
  const auto& at6 = std::get<EncoderTicks>(enc.back().payload);
  EXPECT_LE(std::abs(at6.left_ticks - at5.left_ticks), 2);
  EXPECT_LE(std::abs(at6.right_ticks - at5.right_ticks), 2);
  // Backing off frees it; driving in again is a second contact.
  Drive(robot, -0.2, 0.0, 7.0);
  EXPECT_FALSE(robot.in_contact());
  Drive(robot, 0.3, 0.0, 10.0);
  EXPECT_EQ(robot.collisions(), 2);
}

TEST(SimRobot, RejectsAStartInAWall) {
  World world = Box(1.0);
  EXPECT_THROW(SimRobot(world, SimRobotOptions{}, {0.95, 0, 0}, 1), std::invalid_argument);
  SimRobotOptions bad;
  bad.lidar.beams = 0;
  EXPECT_THROW(SimRobot(world, bad, {0, 0, 0}, 1), std::invalid_argument);
}

// Everything an event carries, exactly.
std::string Fingerprint(const Event& e) {
  std::ostringstream s;
  s << std::hexfloat << e.t_us << ' ' << e.channel << ' ' << int(e.kind) << ':';
  std::visit(
      [&s](const auto& p) {
        using T = std::decay_t<decltype(p)>;
        if constexpr (std::is_same_v<T, Pose2D>) {
          s << p.x << ' ' << p.y << ' ' << p.theta;
        } else if constexpr (std::is_same_v<T, LidarScan>) {
          for (float r : p.ranges_m) s << ' ' << r;
        } else if constexpr (std::is_same_v<T, EncoderTicks>) {
          s << p.left_ticks << ' ' << p.right_ticks;
        } else if constexpr (std::is_same_v<T, Imu>) {
          s << p.gyro_rad_s[2] << ' ' << p.angles_rpy_rad[2];
        } else if constexpr (std::is_same_v<T, MotorCommand>) {
          s << p.velocity.v_m_s << ' ' << p.velocity.w_rad_s << ' ' << p.left_duty << ' ' << p.right_duty;
        } else if constexpr (std::is_same_v<T, WheelSpeeds>) {
          s << p.left_rad_s << ' ' << p.right_rad_s;
        }
      },
      e.payload);
  return s.str();
}

std::vector<std::string> Stream(uint64_t seed) {
  World world = Box(1.5);
  SimRobot robot(world, SimRobotOptions{}, {0, 0, 0}, seed);
  std::vector<Event> events = Drive(robot, 0.3, 0.5, 1.0);
  robot.Command(0.1, -1.0);
  robot.AdvanceTo(2 * kSecond, &events);
  std::vector<std::string> out;
  for (const auto& e : events) out.push_back(Fingerprint(e));
  return out;
}

TEST(SimRobot, SameSeedSameEventsDifferentSeedDifferent) {
  const auto a = Stream(7), b = Stream(7), c = Stream(8);
  ASSERT_FALSE(a.empty());
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
}

// --- SimSource --------------------------------------------------------------------------------

std::string WriteArena(const std::string& name, const std::string& text) {
  const std::string path = test::TempPath(name);
  std::ofstream(path) << text;
  return path;
}

const char* kRoom = "name room\nbox -1.5 -1 1.5 1\npose start -0.5 0 0\n";

SourceOptions ParseSource(const std::string& ini) {
  RegisterSimSource();
  const auto config = config::Config::FromString(ini, "t.ini");
  config::Section s = config.GetSection("source");
  SourceOptions o = ParseSourceOptions(s);
  s.Finish();
  return o;
}

std::string ConfigErrorOf(const std::string& ini) {
  try {
    ParseSource(ini);
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(SimSource, StreamIsTimeOrderedAndEndsAtDuration) {
  const std::string path = WriteArena("room.arena", kRoom);
  RegisterSimSource();
  EXPECT_EQ(DetectFormat(path), "sim");
  SourceOptions o = ParseSource("[source]\npath = " + path + "\nduration_s = 1.5\n");  // type auto
  EXPECT_DOUBLE_EQ(std::any_cast<const SimSourceOptions&>(o.extra).duration_s, 1.5);
  auto source = OpenSource(o);
  EXPECT_EQ(source->Format(), "simulator");
  EXPECT_EQ(source->channels().size(), 8u);
  EXPECT_EQ(source->channels().at("LIDAR").kind, EventKind::kLidar);
  int64_t last = 0;
  size_t n = 0, scans = 0;
  while (auto e = source->Next()) {
    EXPECT_GE(e->t_us, last);
    EXPECT_EQ(e->stamp_us, e->t_us);
    last = e->t_us;
    scans += e->kind == EventKind::kLidar;
    ++n;
  }
  EXPECT_EQ(last, 1500000);
  EXPECT_EQ(scans, 12u);
  EXPECT_GT(n, 500u);
  EXPECT_DOUBLE_EQ(source->Progress(), 1.0);
  EXPECT_FALSE(source->Next());
  auto* sim = dynamic_cast<SimSource*>(source.get());
  ASSERT_NE(sim, nullptr);
  EXPECT_NEAR(sim->robot().true_pose().x, -0.5, 1e-12);  // the arena's start, never commanded
}

TEST(SimSource, VelocityCommandsDriveTheRobot) {
  SourceOptions o;
  o.type = "sim";
  o.path = WriteArena("room_cmd.arena", kRoom);
  SimSourceOptions so;
  so.duration_s = 3.0;
  SimSource sim(o, so);
  Sink& sink = sim;
  auto until = [&sim](double t_s) {
    while (auto e = sim.Next()) {
      if (e->t_us >= t_s * kSecond) return true;
    }
    return false;
  };
  ASSERT_TRUE(until(0.5));
  EXPECT_EQ(sim.robot().distance_travelled_m(), 0.0);
  sink.Send(Event{500000, 500000, "MBOT_VEL_CMD", EventKind::kMotorCommand, MotorCommand::Velocity(0.2, 0.0)});
  sink.Send(Event{500000, 500000, "MBOT_MOTOR_PWM", EventKind::kMotorCommand, MotorCommand::Pwm(0.0, 0.0)});  // ignored
  sink.Send(Event{500000, 500000, "TRUE_POSE", EventKind::kGroundTruth, Pose2D{}});                           // ignored
  ASSERT_TRUE(until(2.5));
  // 0.2 m/s for the firmware's 1 s command timeout, then it stops: no command kept it driving.
  EXPECT_GT(sim.robot().true_pose().x, -0.5 + 0.15);
  EXPECT_LT(sim.robot().distance_travelled_m(), 0.28);
  EXPECT_NEAR(sim.Progress(), 2.5 / 3.0, 0.01);
  sim.RequestEnd();
  EXPECT_FALSE(sim.Next());
  EXPECT_DOUBLE_EQ(sim.Progress(), 1.0);
  EXPECT_LT(sim.robot().now_us(), 3 * kSecond);
}

TEST(SimSource, OptionsAreStrictAndOnlyForTheSimulator) {
  const std::string arena = WriteArena("room_opts.arena", kRoom);
  const std::string base = "[source]\ntype = sim\npath = " + arena + "\n";
  const SourceOptions o = ParseSource(base +
                                      "start = 1, -0.5, 90\nlidar_beams = 720\nright_motor_gain = 0.9\n"
                                      "firmware_rate_hz = 100\n");
  const auto& so = std::any_cast<const SimSourceOptions&>(o.extra);
  ASSERT_TRUE(so.start.has_value());
  EXPECT_DOUBLE_EQ(so.start->x, 1.0);
  EXPECT_DOUBLE_EQ(so.start->theta, M_PI / 2);
  EXPECT_EQ(so.robot.lidar.beams, 720);
  EXPECT_DOUBLE_EQ(so.robot.right_motor_gain, 0.9);
  EXPECT_DOUBLE_EQ(so.robot.controller.dt_s, 0.01);
  EXPECT_DOUBLE_EQ(so.duration_s, 600.0);

  std::string e = ConfigErrorOf(base + "lidar_beam = 720\n");
  EXPECT_NE(e.find("[source] lidar_beam: unknown key"), std::string::npos) << e;
  e = ConfigErrorOf(base + "lidar_dropout = 2\n");
  EXPECT_NE(e.find("[source] lidar_dropout"), std::string::npos) << e;
  e = ConfigErrorOf(base + "start = 1, 2\n");
  EXPECT_NE(e.find("[source] start"), std::string::npos) << e;
  // A start in a wall is an error naming the world file.
  SourceOptions in_wall = ParseSource(base + "start = 1.45, 0, 0\n");
  try {
    SimSource sim(in_wall, std::any_cast<const SimSourceOptions&>(in_wall.extra));
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& err) {
    const std::string what = err.what();
    EXPECT_NE(what.find("room_opts.arena: sim robot: the start pose"), std::string::npos) << what;
  }
  // A grid world has no start pose and needs none: it starts where it has the most room.
  e = ConfigErrorOf("[source]\ntype = sim\npath = /somewhere/maze.map\n");
  EXPECT_EQ(e.find("[source] start"), std::string::npos) << e;
  // Simulator keys are unknown for any other source.
  e = ConfigErrorOf("[source]\ntype = lcm_log\npath = x.log\nduration_s = 5\n");
  EXPECT_NE(e.find("[source] duration_s: unknown key"), std::string::npos) << e;
}

// Not a pass/fail figure: how fast the simulator runs with default options on a maze-sized arena
// (4.8 m square, 8 x 8 cells of 0.6 m, internal walls), every event drained.
TEST(SimSource, SpeedOnAMazeArena) {
  std::ostringstream a;
  a << "name maze\nbox 0 0 4.8 4.8\npose start 0.3 0.3 0\n";
  for (int i = 1; i < 8; ++i) {
    for (int j = 0; j < 8; ++j) {
      const double u = i * 0.6, v0 = j * 0.6, v1 = (j + 1) * 0.6;
      if ((i * 5 + j * 3) % 4 == 0) a << "wall " << u << ' ' << v0 << ' ' << u << ' ' << v1 << '\n';  // vertical
      if ((i * 3 + j * 7) % 4 == 1) a << "wall " << v0 << ' ' << u << ' ' << v1 << ' ' << u << '\n';  // horizontal
    }
  }
  SourceOptions o;
  o.type = "sim";
  o.path = WriteArena("maze.arena", a.str());
  SimSourceOptions so;
  so.duration_s = 60.0;
  SimSource sim(o, so);
  // A roaming robot: drive ahead, turn in place when a wall is near in front (a cheap bumper on the
  // true pose, every 10 ms, so the figure is for a moving robot, not one pushing against a wall).
  const auto t0 = std::chrono::steady_clock::now();
  size_t n = 0;
  bool turning = false;
  while (auto e = sim.Next()) {
    ++n;
    if (e->kind != EventKind::kGroundTruth) continue;
    const Pose2D& p = PoseOf(*e);
    // A turn goes on until the way ahead is clear by more than the distance that stopped it (the
    // robot's command filters lag 0.17 s and 0.22 s: without the margin it dithers at the threshold).
    bool blocked = false, clear = true;
    for (double a : {-1.2, -0.6, 0.0, 0.6, 1.2}) {
      const double range = sim.world().Raycast(p.x, p.y, p.theta + a, 1.0);
      blocked = blocked || range < 0.3;
      if (std::abs(a) < 1.0) clear = clear && range >= 0.4;
    }
    turning = turning ? !clear : blocked;
    sim.Send(Event{e->t_us, e->t_us, "MBOT_VEL_CMD", EventKind::kMotorCommand,
                   MotorCommand::Velocity(turning ? 0.0 : 0.3, turning ? 1.5 : 0.0)});
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double speed = so.duration_s / wall;
  std::cout << "[ sim      ] " << n << " events, " << so.duration_s << " s simulated in " << wall * 1e3
            << " ms: " << speed << " x real time (" << sim.world().walls().size() << " walls, "
            << sim.robot().distance_travelled_m() << " m driven, " << sim.robot().collisions() << " collisions)\n";
  RecordProperty("sim_seconds_per_wall_second", std::to_string(speed));
  EXPECT_GT(n, 20000u);
  EXPECT_GT(sim.robot().distance_travelled_m(), 2.5);  // it roams: 3.7 m (the lagging robot turns longer)
}

// A crate in front of the robot: the lidar sees its face, and driving into it is a collision.
TEST(SimRobot, CratesAreSeenByTheLidarAndBlockTheBody) {
  World world = World::ParseArena("box -2 -2 2 2\ncrate 3 0.6 0 0\n", "crate.arena");
  SimRobotOptions o;
  o.lidar.range_noise_m = 0.0;
  o.lidar.dropout = 0.0;
  SimRobot robot(world, o, {0, 0, 0}, 4);
  const auto events = Drive(robot, 0, 0, 0.13);
  const auto scans = OfKind(events, EventKind::kLidar);
  ASSERT_EQ(scans.size(), 1u);
  const auto& scan = std::get<LidarScan>(scans[0].payload);
  const Pose2D sensor = Pose2D{0, 0, 0}.Compose(o.lidar.mount);
  EXPECT_NEAR(scan.ranges_m[0], 0.55 - sensor.x, 1e-5);  // beam 0 looks straight ahead at the face
  const auto drove = Drive(robot, 0.2, 0, 4.0);
  EXPECT_GE(robot.collisions(), 1);
  EXPECT_LT(robot.true_pose().x, 0.55 - o.footprint_radius_m + 0.01);  // stopped at the crate's face
}

// crates_at_random: the run's seed places the crates (the same seed, the same crates), inside the
// square, clear of the start; more than fit is an error naming the file.
TEST(SimSource, CratesAtRandomComeFromTheSeed) {
  const std::string path = WriteArena("crates.arena", std::string(kRoom) + "crates_at_random 3 0.6 0 0.8 5\n");
  auto crates_of = [&](uint64_t seed) {
    SourceOptions o = ParseSource("[source]\ntype = sim\npath = " + path + "\n");
    o.seed = seed;
    auto source = OpenSource(o);
    return dynamic_cast<SimSource&>(*source).world().crates();
  };
  const std::vector<Crate> a = crates_of(1), b = crates_of(1), c = crates_of(2);
  ASSERT_EQ(a.size(), 3u);
  for (size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].id, static_cast<int>(5 + k));
    EXPECT_EQ(a[k].pose.x, b[k].pose.x);
    EXPECT_EQ(a[k].pose.theta, b[k].pose.theta);
    EXPECT_LE(std::abs(a[k].pose.x - 0.6), 0.4);
    EXPECT_LE(std::abs(a[k].pose.y), 0.4);
    EXPECT_GE(a[k].DistanceTo(-0.5, 0.0), 0.2);  // the start, clear by footprint + 0.1 m
  }
  EXPECT_NE(a[0].pose.x, c[0].pose.x);
  const std::string crowded = WriteArena("crowded.arena", std::string(kRoom) + "crates_at_random 20 0.6 0 0.3 1\n");
  try {
    OpenSource(ParseSource("[source]\ntype = sim\npath = " + crowded + "\n"));
    FAIL() << "20 crates fitted in a 0.3 m square";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("crowded.arena: crates_at_random: only"), std::string::npos) << e.what();
  }
  EXPECT_NE(std::string(World::ParseArena("box -1 -1 1 1\n", "x").crate_area() ? "set" : "none"), "set");
}

}  // namespace
}  // namespace mbot::sim
