// The CDR codec's own rules on bytes written by hand (rosbags' bytes: tests/ros2/rosbags_interop.py).
#include "mbot/ros2/cdr.hpp"

#include <gtest/gtest.h>

#include <cstring>

#include "mbot/ros2/messages.hpp"

namespace mbot::ros2 {
namespace {

TEST(Cdr, TwistIsSixDoublesAfterTheHeader) {
  const std::vector<uint8_t> b = Encode(Twist{{1, 2, 3}, {4, 5, 6}});
  ASSERT_EQ(b.size(), 4u + 48u);
  EXPECT_EQ(b[0], 0x00);
  EXPECT_EQ(b[1], 0x01);  // little-endian plain CDR
  const Twist t = DecodeTwist(b.data(), b.size());
  EXPECT_EQ(t.linear.x, 1);
  EXPECT_EQ(t.angular.z, 6);
}

TEST(Cdr, AlignmentCountsFromAfterTheHeader) {
  // Odometry: stamp (8), "odom" (4 + 5), child "b" (pad to 4, then 4 + 2), pad to 8, position.
  Odometry o;
  o.header.frame_id = "odom";
  o.child_frame_id = "b";
  o.pose.position.x = 7.5;
  const std::vector<uint8_t> b = Encode(o);
  // 8 + 9 = 17 → 20, + 6 = 26 → 32: the position's x at payload offset 32.
  double x;
  std::memcpy(&x, b.data() + 4 + 32, 8);
  EXPECT_EQ(x, 7.5);
  EXPECT_EQ(DecodeOdometry(b.data(), b.size()).pose.position.x, 7.5);
}

TEST(Cdr, BadPayloadsNameTheFieldAndOffset) {
  LaserScan s;
  s.header.frame_id = "laser";
  s.ranges = {1, 2, 3};
  std::vector<uint8_t> b = Encode(s);
  // Cut inside the ranges.
  try {
    DecodeLaserScan(b.data(), b.size() - 8);
    FAIL() << "a cut scan was read";
  } catch (const CdrError& e) {
    EXPECT_NE(std::string(e.what()).find("ranges"), std::string::npos) << e.what();
  }
  // Big-endian encapsulation is refused.
  std::vector<uint8_t> be = b;
  be[1] = 0x00;
  EXPECT_THROW(DecodeLaserScan(be.data(), be.size()), CdrError);
  // A string without its NUL.
  std::vector<uint8_t> nul = b;
  nul[4 + 8 + 4 + 5] = 'x';  // "laser\0" → "laserx"
  EXPECT_THROW(DecodeLaserScan(nul.data(), nul.size()), CdrError);
  // Shorter than the header.
  EXPECT_THROW(DecodeTwist(b.data(), 3), CdrError);
}

// std_srvs/Trigger as it travels: the request alone (one placeholder byte), or with rmw_cyclonedds's
// 16-byte header (client handle, sequence) in front, which a server echoes in its reply.
TEST(Cdr, TriggerRequestsAndResponsesInBothForms) {
  const std::vector<uint8_t> plain = EncodeTriggerRequest();
  EXPECT_EQ(plain, (std::vector<uint8_t>{0, 1, 0, 0, 0}));
  ServiceHeader h;
  EXPECT_FALSE(DecodeTriggerRequest(plain.data(), plain.size(), &h));
  std::vector<uint8_t> padded = plain;  // as Fast DDS pads it on the wire
  padded.resize(8, 0);
  EXPECT_FALSE(DecodeTriggerRequest(padded.data(), padded.size(), &h));
  const ServiceHeader sent{0x0102030405060708ULL, 42};
  const std::vector<uint8_t> with = EncodeTriggerRequest(&sent);
  ASSERT_EQ(with.size(), 21u);
  EXPECT_TRUE(DecodeTriggerRequest(with.data(), with.size(), &h));
  EXPECT_EQ(h.guid, sent.guid);
  EXPECT_EQ(h.sequence, 42);
  const std::vector<uint8_t> reply = Encode(TriggerResponse{true, "Odometry reset to (0, 0, 0)"});
  // bool, 3 bytes of padding, the length with the NUL, the text.
  ASSERT_EQ(reply.size(), 4u + 4 + 4 + 28);
  EXPECT_EQ(reply[8], 28);
  const TriggerResponse back = DecodeTriggerResponse(reply.data(), reply.size());
  EXPECT_TRUE(back.success);
  EXPECT_EQ(back.message, "Odometry reset to (0, 0, 0)");
  EXPECT_EQ(Encode(TriggerResponse{true, "x"}, &sent).size(), 4u + 16 + 4 + 4 + 2);
  const std::vector<uint8_t> cut(reply.begin(), reply.begin() + 10);
  EXPECT_THROW(DecodeTriggerResponse(cut.data(), cut.size()), CdrError);
}

TEST(Cdr, YawRoundTrips) {
  EXPECT_NEAR(Yaw(FromYaw(2.5)), 2.5, 1e-12);
  EXPECT_NEAR(Yaw(FromYaw(-3.0)), -3.0, 1e-12);
}

}  // namespace
}  // namespace mbot::ros2
