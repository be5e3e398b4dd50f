#include "mbot/motion/pose2d.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace mbot::motion {
namespace {

TEST(Pose2DTest, ComposeWithInverseIsIdentity) {
  const Pose2D p{1.0, -2.0, 2.5};
  const Pose2D id = p.Compose(p.Inverse());
  EXPECT_NEAR(id.x, 0, 1e-12);
  EXPECT_NEAR(id.y, 0, 1e-12);
  EXPECT_NEAR(id.theta, 0, 1e-12);
}

TEST(Pose2DTest, WrapAndInterpolateTakeTheShortArc) {
  EXPECT_NEAR(WrapAngle(3 * M_PI), M_PI, 1e-12);
  EXPECT_NEAR(WrapAngle(-M_PI / 2 - 2 * M_PI), -M_PI / 2, 1e-12);
  const Pose2D m = Interpolate({0, 0, 3.0}, {2, 2, -3.0}, 0.5);
  EXPECT_NEAR(std::abs(m.theta), M_PI, 1e-9);
  EXPECT_NEAR(m.x, 1.0, 1e-12);
}

TEST(Pose2DTest, InterpolateAtRespectsGaps) {
  std::vector<TimedPose> s = {{0, {0, 0, 0}}, {100, {1, 0, 0}}, {1000, {2, 0, 0}}};
  Pose2D out;
  ASSERT_TRUE(InterpolateAt(s, 50, 200, &out));
  EXPECT_NEAR(out.x, 0.5, 1e-12);
  EXPECT_FALSE(InterpolateAt(s, 500, 200, &out));   // neighbours 900 us apart
  EXPECT_FALSE(InterpolateAt(s, 5000, 200, &out));  // past the end
}

}  // namespace
}  // namespace mbot::motion
