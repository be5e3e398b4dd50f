// The fault relay's faults on the injector's own clock, no bus: each fault alone at a known rate,
// seeded (the same seed, the same faults), and the channels and silences they apply to.
#include "mbot/lcm/fault_injector.hpp"

#include <gtest/gtest.h>

namespace mbot::lcmio {
namespace {

std::vector<uint8_t> Bytes(int k) { return {static_cast<uint8_t>(k), 1, 2, 3, 4, 5, 6, 7}; }

// 1000 messages on LIDAR 10 ms apart, each taken out at its arrival plus `drain_s`.
std::vector<FaultInjector::Message> Cross(FaultInjector& f, double drain_s = 0.0,
                                          const std::string& channel = "LIDAR") {
  std::vector<FaultInjector::Message> out;
  for (int k = 0; k < 1000; ++k) {
    f.Receive(true, channel, Bytes(k), k * 0.01);
    for (auto& m : f.TakeDue(k * 0.01 + drain_s)) out.push_back(std::move(m));
  }
  for (auto& m : f.TakeDue(1e9)) out.push_back(std::move(m));
  return out;
}

TEST(FaultInjector, WithoutFaultsEveryMessageCrossesAtOnceInOrder) {
  FaultInjector f(FaultOptions{});
  const auto out = Cross(f);
  ASSERT_EQ(out.size(), 1000u);
  for (int k = 0; k < 1000; ++k) {
    EXPECT_EQ(out[k].data, Bytes(k));
    EXPECT_DOUBLE_EQ(out[k].due_s, k * 0.01);
  }
  EXPECT_EQ(f.stats().at("LIDAR").relayed, 1000);
}

TEST(FaultInjector, DropsDuplicatesAndCorruptionComeAtTheirRatesAndTheSeedRepeatsThem) {
  FaultOptions o;
  o.drop_rate = 0.2;
  o.duplicate_rate = 0.1;
  o.corrupt_rate = 0.05;
  o.seed = 7;
  FaultInjector a(o), b(o);
  const auto out_a = Cross(a), out_b = Cross(b);
  const RelayChannelStats& s = a.stats().at("LIDAR");
  EXPECT_NEAR(s.dropped, 200, 40);
  EXPECT_NEAR(s.duplicated, 80, 25);  // of the 80 % not dropped
  EXPECT_NEAR(s.corrupted, 40, 18);
  EXPECT_EQ(static_cast<long long>(out_a.size()), 1000 - s.dropped + s.duplicated);
  int changed = 0;
  for (const auto& m : out_a) changed += m.data != Bytes(m.data[0]) || m.data.size() != 8;
  EXPECT_GT(changed, 0);
  EXPECT_LE(changed, 2 * s.corrupted);  // a corrupted message may also be duplicated
  ASSERT_EQ(out_a.size(), out_b.size());
  for (size_t i = 0; i < out_a.size(); ++i) EXPECT_EQ(out_a[i].data, out_b[i].data);
}

TEST(FaultInjector, AReorderedMessageGoesOutRightAfterTheChannelsNextOne) {
  FaultOptions o;
  o.reorder_rate = 0.1;
  FaultInjector f(o);
  const auto out = Cross(f);
  ASSERT_EQ(out.size(), 1000u);  // nothing lost: a held message leaves with the next one
  int swaps = 0;
  for (size_t i = 1; i < out.size(); ++i) {
    if (out[i].data[0] == static_cast<uint8_t>(out[i - 1].data[0] - 1)) ++swaps;
  }
  EXPECT_EQ(swaps, f.stats().at("LIDAR").reordered);
  EXPECT_NEAR(swaps, 90, 30);
}

TEST(FaultInjector, DelayAndJitterHoldMessagesBack) {
  FaultOptions o;
  o.delay_ms = 50;
  o.jitter_ms = 20;
  FaultInjector f(o);
  f.Receive(true, "LIDAR", Bytes(0), 1.0);
  EXPECT_TRUE(f.TakeDue(1.049).empty());
  ASSERT_TRUE(f.next_due_s().has_value());
  EXPECT_GE(*f.next_due_s(), 1.05);
  EXPECT_LE(*f.next_due_s(), 1.07);
  EXPECT_EQ(f.TakeDue(1.07).size(), 1u);
}

TEST(FaultInjector, SilencesAndFaultChannelsApplyToTheirChannelsOnly) {
  FaultOptions o;
  o.drop_rate = 1.0;
  o.channels = {"LIDAR"};
  o.silences = {{"MBOT_ODOMETRY", 2.0, 3.0}};
  FaultInjector f(o);
  EXPECT_TRUE(Cross(f, 0.0, "LIDAR").empty());           // every LIDAR message lost
  const auto odometry = Cross(f, 0.0, "MBOT_ODOMETRY");  // not a fault channel, but silenced 2-5 s
  EXPECT_EQ(f.stats().at("MBOT_ODOMETRY").silenced, 300);
  EXPECT_EQ(odometry.size(), 700u);
  for (const auto& m : odometry) EXPECT_TRUE(m.due_s < 2.0 || m.due_s >= 5.0) << m.due_s;
}

}  // namespace
}  // namespace mbot::lcmio
