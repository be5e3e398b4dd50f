// The `mixed` fault scenario on the odometry alone, without a bus: a robot's MBOT_ODOMETRY as the
// simulated robot publishes it (pose2D_t, 50 Hz, turning in place at 2.5 rad/s and driving at
// 0.3 m/s), through the fault relay's injector (5 % drops, 5 % duplicates, 5 % reordered, 2 % with
// 1-4 corrupted bytes, 20 ms + 0-20 ms), decoded and checked as the live source does, into SLAM's
// inputs at their arrival times (SLAM's default time base) and to the mission's own continuity
// check. The robot never restarts, so neither may take a jump for a restart: each one the live
// `mixed` runs took sent SLAM and the mission off their map.
#include <gtest/gtest.h>

#include <cmath>

#include "lcm_messages.hpp"
#include "mbot/lcm/fault_injector.hpp"
#include "mbot/lcm/lcm_live.hpp"
#include "mbot/mapping/slam_session.hpp"
#include "mbot/motion/odometry_continuity.hpp"

namespace mbot::lcmio {
namespace {

using msgs::Event;
using msgs::EventKind;

// The robot: 1 s turning in place, then 2 s straight, over and over.
motion::Pose2D RobotAt(double t) {
  motion::Pose2D p;
  double done = 0;
  while (done + 3.0 <= t) {
    p = p.Compose({0, 0, 2.5}).Compose({0.6, 0, 0});
    done += 3.0;
  }
  const double s = t - done;
  if (s < 1.0) return p.Compose({0, 0, 2.5 * s});
  return p.Compose({0, 0, 2.5}).Compose({0.3 * (s - 1.0), 0, 0});
}

TEST(MixedFaults, CorruptDuplicatedAndReorderedOdometryNeverReadsAsARestart) {
  int restarts = 0, messages = 0, taken = 0;
  std::string first;
  int mission_restarts = 0;
  for (uint64_t seed = 1; seed <= 100; ++seed) {
    FaultOptions o;
    o.drop_rate = 0.05, o.duplicate_rate = 0.05, o.reorder_rate = 0.05, o.corrupt_rate = 0.02;
    o.delay_ms = 20, o.jitter_ms = 20, o.seed = seed;
    FaultInjector relay(o);
    mapping::SlamSessionOptions so;
    mapping::SlamInputs inputs(so, 1);
    motion::OdometryContinuity mission;  // as the mission keeps it: arrival times, the stamps beside
    int64_t mission_last_us = -1;
    const int64_t t0 = 1'700'000'000'000'000;  // the wall clock both ends share
    auto deliver = [&](double now) {
      int64_t apart = 0;  // messages due at once reach the receive thread microseconds apart
      for (const FaultInjector::Message& m : relay.TakeDue(now)) {
        Event ev;
        std::string error;
        if (!lcm_adapter::Decode(m.channel, m.data.data(), m.data.size(), msgs::ChannelRoles{}, &ev, &error)) continue;
        if (!msgs::IsPlausibleTimeUs(ev.stamp_us)) continue;
        ev.channel = m.channel;
        ev.t_us = t0 + static_cast<int64_t>(std::llround(m.due_s * 1e6)) + apart++;
        taken += inputs.Add(ev);
        if (ev.t_us >= mission_last_us) {
          mission.Update(ev.t_us, std::get<motion::Pose2D>(ev.payload), ev.stamp_us);
          mission_last_us = ev.t_us;
        }
        if (inputs.odometry_restarts() > 0 && first.empty()) {
          const auto& j = inputs.continuity().last_restart();
          first = "seed " + std::to_string(seed) + ": " + std::to_string(j.before.x) + "," +
                  std::to_string(j.before.y) + "," + std::to_string(j.before.theta) + " @" +
                  std::to_string(j.before_us - t0) + " -> " + std::to_string(j.jumped.x) + "," +
                  std::to_string(j.jumped.y) + "," + std::to_string(j.jumped.theta) + " @" +
                  std::to_string(j.jumped_us - t0) + " -> " + std::to_string(j.confirmed.x) + "," +
                  std::to_string(j.confirmed.y) + "," + std::to_string(j.confirmed.theta) + " @" +
                  std::to_string(j.confirmed_us - t0);
        }
      }
    };
    for (int k = 0; k < 3000; ++k) {  // 60 s at 50 Hz
      const double t = k * 0.02;
      const Event ev{t0 + k * 20'000, t0 + k * 20'000, "MBOT_ODOMETRY", EventKind::kOdometry, RobotAt(t)};
      relay.Receive(true, ev.channel, EncodeEvent(ev), t);
      ++messages;
      deliver(t);
    }
    deliver(1e9);
    restarts += inputs.odometry_restarts();
    mission_restarts += mission.restarts();
  }
  EXPECT_EQ(restarts, 0) << first;
  EXPECT_EQ(mission_restarts, 0);
  EXPECT_GT(taken, messages * 8 / 10);
}

}  // namespace
}  // namespace mbot::lcmio
