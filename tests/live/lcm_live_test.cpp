// The live LCM edge, over real LCM (udpm multicast) inside a private network namespace (ctest runs
// this binary through tests/live/in_netns.sh; outside one, the tests say so and are skipped).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <thread>

#include "mbot/lcm/lcm_live.hpp"
#include "mbot/drivers/map_io.hpp"
#include "mbot/msgs/sink.hpp"
#include "mbot/msgs/source.hpp"
#include "mbot/lcm/lcm_sources.hpp"

namespace mbot::lcmio {

using namespace msgs;  // the event vocabulary
namespace {

// A port of its own per test binary run; ttl=0 keeps it on the machine (the namespace's loopback).
const char* kUrl = "udpm://239.255.76.67:7671?ttl=0";

bool InNamespace() { return std::getenv("MBOT_NETNS") != nullptr; }

// Pulls events from the source for `seconds`, keeping the non-heartbeat ones.
std::vector<Event> Drain(Source& source, double seconds) {
  std::vector<Event> got;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    auto ev = source.Next();
    if (!ev) break;
    if (ev->channel != "LIVE_TICK") got.push_back(std::move(*ev));
  }
  return got;
}

SourceOptions LiveOptions() {
  SourceOptions o;
  o.type = "lcm_live";
  o.path = kUrl;
  LiveSourceOptions live;
  live.stale_sensor_s = 0.3;
  live.report_every_s = 0;
  o.extra = live;
  return o;
}

TEST(LcmLive, MalformedPacketsOnEverySubscribedChannelAreRejectedAndCountedAndTheRestPasses) {
  ASSERT_TRUE(InNamespace()) << "run through tests/live/in_netns.sh (a private network namespace), as ctest does";
  SourceOptions o = LiveOptions();
  auto source = OpenSource(o);
  LcmNode robot(kUrl, {}, {});
  // Well-formed messages to break.
  LidarScan scan;
  scan.ranges_m = {1.0f, 2.0f, 3.0f};
  scan.angles_rad = {0.0f, 0.1f, 0.2f};
  const std::vector<uint8_t> lidar = EncodeEvent(Event{0, 5, "LIDAR", EventKind::kLidar, scan});
  const std::vector<uint8_t> pose =
      EncodeEvent(Event{0, 5, "MBOT_ODOMETRY", EventKind::kOdometry, msgs::Pose2D{1, 2, 0.5}});
  ASSERT_FALSE(lidar.empty());
  ASSERT_EQ(pose.size(), 8u + 8 + 12);
  int bad = 0;
  for (const std::string& channel : ExtraOr<LiveSourceOptions>(o).channels) {
    std::vector<uint8_t> truncated(lidar.begin(), lidar.begin() + lidar.size() / 2);
    std::vector<uint8_t> wrong_fingerprint = pose;
    wrong_fingerprint[0] ^= 0x5a;
    std::vector<uint8_t> short_packet = {1, 2, 3};
    robot.PublishRaw(channel, truncated);
    robot.PublishRaw(channel, wrong_fingerprint);
    robot.PublishRaw(channel, short_packet);
    bad += 3;
  }
  std::vector<uint8_t> too_many = lidar;  // num_ranges (after fingerprint and utime) says 1000
  too_many[16] = 0, too_many[17] = 0, too_many[18] = 0x03, too_many[19] = 0xe8;
  robot.PublishRaw("LIDAR", too_many);
  std::vector<uint8_t> nan_pose = pose;  // x = NaN
  nan_pose[16] = 0x7f, nan_pose[17] = 0xc0, nan_pose[18] = 0, nan_pose[19] = 0;
  robot.PublishRaw("MBOT_ODOMETRY", nan_pose);
  robot.PublishRaw("MBOT_ODOMETRY",
                   EncodeEvent(Event{0, -5, "MBOT_ODOMETRY", EventKind::kOdometry, msgs::Pose2D{1, 2, 0.5}}));
  bad += 3;                                 // and a negative utime
  robot.PublishRaw("MBOT_ODOMETRY", pose);  // and one good message: it still passes
  const std::vector<Event> got = Drain(*source, 0.5);
  EXPECT_EQ(source->diagnostics().rejected_messages, bad);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].kind, EventKind::kOdometry);
  EXPECT_EQ(std::get<msgs::Pose2D>(got[0].payload).x, 1.0);
  bool named = false;
  for (const auto& [k, v] : source->Details()) named = named || k == "rejected on LIDAR";
  EXPECT_TRUE(named);
}

TEST(LcmLive, ASilentSensorStopsTheRobotAndHoldsCommandsBack) {
  ASSERT_TRUE(InNamespace()) << "run through tests/live/in_netns.sh (a private network namespace), as ctest does";
  auto source = OpenSource(LiveOptions());
  auto* sink = dynamic_cast<Sink*>(source.get());
  ASSERT_NE(sink, nullptr);
  LcmNode robot(kUrl, {"MBOT_VEL_CMD"}, {});
  // Nothing arrives: after stale_sensor_s (0.3 s) the source publishes zero velocity by itself.
  Drain(*source, 0.6);
  std::vector<Event> cmds;
  robot.Poll(100, &cmds);
  ASSERT_FALSE(cmds.empty());
  for (const Event& c : cmds) {
    const auto& m = std::get<MotorCommand>(c.payload);
    EXPECT_EQ(m.velocity.v_m_s, 0.0);
    EXPECT_EQ(m.velocity.w_rad_s, 0.0);
  }
  EXPECT_LE(cmds.size(), 5u) << "zero velocity at 10 Hz, not on every loop";
  // A command from the stack while the sensors are silent goes out as zero.
  sink->Send(Event{0, 0, "MBOT_VEL_CMD", EventKind::kMotorCommand, MotorCommand::Velocity(0.3, 0.5)});
  cmds.clear();
  robot.Poll(100, &cmds);
  ASSERT_FALSE(cmds.empty());
  EXPECT_EQ(std::get<MotorCommand>(cmds.back().payload).velocity.v_m_s, 0.0);
  bool held = false;
  for (const auto& [k, v] : source->Details()) held = held || (k == "commands held back" && v == "1");
  EXPECT_TRUE(held);
  // The sensors come back: commands pass again.
  LidarScan scan;
  scan.ranges_m = {1.0f};
  scan.angles_rad = {0.0f};
  robot.Publish(Event{0, 5, "LIDAR", EventKind::kLidar, scan});
  robot.Publish(Event{0, 5, "MBOT_ODOMETRY", EventKind::kOdometry, msgs::Pose2D{}});
  Drain(*source, 0.2);
  sink->Send(Event{0, 0, "MBOT_VEL_CMD", EventKind::kMotorCommand, MotorCommand::Velocity(0.3, 0.5)});
  cmds.clear();
  robot.Poll(100, &cmds);
  while (robot.stats().at("MBOT_VEL_CMD").received < 1000) {  // take everything that came
    std::vector<Event> more;
    robot.Poll(20, &more);
    if (more.empty()) break;
    cmds.insert(cmds.end(), more.begin(), more.end());
  }
  ASSERT_FALSE(cmds.empty());
  EXPECT_FLOAT_EQ(std::get<MotorCommand>(cmds.back().payload).velocity.v_m_s, 0.3f);
}

// Called by explore_over_lcm.sh with the live run's map and the map its lcm-logger recording
// replayed to: of the cells either map knows, at least 95 % are the same (free, wall or unknown).
TEST(LiveReplay, TheRecordedRunReplaysToTheLiveMap) {
  const char* live_path = std::getenv("MBOT_LIVE_MAP");
  const char* replay_path = std::getenv("MBOT_REPLAY_MAP");
  ASSERT_TRUE(live_path && replay_path) << "run by tests/live/explore_over_lcm.sh (MBOT_LIVE_MAP, MBOT_REPLAY_MAP)";
  const msgs::OccupancyGrid live = drivers::ReadBotlabMap(live_path), replay = drivers::ReadBotlabMap(replay_path);
  ASSERT_EQ(live.width(), replay.width());
  ASSERT_EQ(live.height(), replay.height());
  auto cls = [](int v) { return v > 0 ? 1 : v < 0 ? -1 : 0; };
  long known = 0, same = 0;
  for (size_t i = 0; i < live.cells().size(); ++i) {
    const int a = cls(live.cells()[i]), b = cls(replay.cells()[i]);
    if (a == 0 && b == 0) continue;
    ++known;
    same += a == b;
  }
  ASSERT_GT(known, 1000);
  const double agreement = double(same) / known;
  RecordProperty("agreement", std::to_string(agreement));
  std::cout << "map agreement " << agreement << " over " << known << " known cells\n";
  EXPECT_GE(agreement, 0.95);
}

}  // namespace
}  // namespace mbot::lcmio
