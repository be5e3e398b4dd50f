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

TEST(Cdr, YawRoundTrips) {
  EXPECT_NEAR(Yaw(FromYaw(2.5)), 2.5, 1e-12);
  EXPECT_NEAR(Yaw(FromYaw(-3.0)), -3.0, 1e-12);
}

}  // namespace
}  // namespace mbot::ros2
