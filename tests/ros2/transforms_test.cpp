// The /tf_static tree the mcap source takes the lidar's mount from: chains, the MBot's 180° lidar,
// an upside-down mount, and what it refuses (loops, a second parent, non-finite values).
#include "mbot/ros2/transforms.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace mbot::ros2 {
namespace {

TransformStamped Edge(const std::string& parent, const std::string& child, double x, double z, Quaternion q) {
  TransformStamped t;
  t.header.frame_id = parent;
  t.child_frame_id = child;
  t.transform.translation = {x, 0.0, z};
  t.transform.rotation = q;
  return t;
}

TEST(StaticTransforms, ChainsTheMbotsLidarMount) {
  StaticTransforms tf;
  // robot_state_publisher's: base_footprint → base_link (z 0.042) → lidar_link (x 0.05, z 0.142, yaw π).
  EXPECT_EQ(tf.Add({{Edge("base_footprint", "base_link", 0.0, 0.042, FromYaw(0.0)),
                     Edge("base_link", "lidar_link", 0.05, 0.142, FromYaw(M_PI))}}),
            "");
  const auto t = tf.Lookup("base_footprint", "lidar_link");
  ASSERT_TRUE(t.has_value());
  EXPECT_NEAR(t->translation.x, 0.05, 1e-12);
  EXPECT_NEAR(t->translation.z, 0.184, 1e-12);
  EXPECT_NEAR(std::abs(Yaw(t->rotation)), M_PI, 1e-12);
  // The other way round is the inverse, and a frame in itself is the identity.
  const auto back = tf.Lookup("lidar_link", "base_footprint");
  ASSERT_TRUE(back.has_value());
  EXPECT_NEAR(back->translation.x, 0.05, 1e-12);  // behind a lidar that faces backwards
  EXPECT_NEAR(back->translation.z, -0.184, 1e-12);
  EXPECT_FALSE(tf.Lookup("base_footprint", "camera_link").has_value());
}

TEST(StaticTransforms, SiblingsMeetAtTheirCommonParent) {
  StaticTransforms tf;
  tf.Add({{Edge("base_link", "lidar_link", 0.1, 0.0, FromYaw(M_PI / 2)),
           Edge("base_link", "camera_link", -0.1, 0.0, FromYaw(0.0))}});
  const auto t = tf.Lookup("camera_link", "lidar_link");
  ASSERT_TRUE(t.has_value());
  EXPECT_NEAR(t->translation.x, 0.2, 1e-12);
  EXPECT_NEAR(Yaw(t->rotation), M_PI / 2, 1e-12);
}

TEST(StaticTransforms, AnUpsideDownMountTurnsTheScanPlaneOver) {
  StaticTransforms tf;
  tf.Add({{Edge("base_link", "laser", 0.0, 0.2, {1.0, 0.0, 0.0, 0.0})}});  // roll π
  const auto t = tf.Lookup("base_link", "laser");
  ASSERT_TRUE(t.has_value());
  EXPECT_LT(Rotate(t->rotation, {0, 0, 1}).z, -0.99);
  EXPECT_NEAR(Rotate(t->rotation, {0, 1, 0}).y, -1.0, 1e-12);  // its +y (a beam at +90°) points right
}

TEST(StaticTransforms, RefusesLoopsSecondParentsAndNonFiniteValues) {
  StaticTransforms tf;
  EXPECT_EQ(tf.Add({{Edge("a", "b", 1, 0, FromYaw(0)), Edge("b", "c", 1, 0, FromYaw(0))}}), "");
  const std::string loop = tf.Add({{Edge("c", "a", 1, 0, FromYaw(0))}});
  EXPECT_NE(loop.find("loop"), std::string::npos) << loop;
  const std::string two = tf.Add({{Edge("x", "c", 1, 0, FromYaw(0))}});
  EXPECT_NE(two.find("two parents"), std::string::npos) << two;
  const std::string nan = tf.Add({{Edge("c", "d", NAN, 0, FromYaw(0))}});
  EXPECT_NE(nan.find("not finite"), std::string::npos) << nan;
  EXPECT_NE(tf.Add({{Edge("e", "e", 0, 0, FromYaw(0))}}), "");
  // The tree is as it was: a → b → c, and nothing hangs off it that was refused.
  ASSERT_TRUE(tf.Lookup("a", "c").has_value());
  EXPECT_NEAR(tf.Lookup("a", "c")->translation.x, 2.0, 1e-12);
  EXPECT_FALSE(tf.Lookup("a", "d").has_value());
  // The same edge again (a republished /tf_static) is not a second parent.
  EXPECT_EQ(tf.Add({{Edge("b", "c", 1.5, 0, FromYaw(0))}}), "");
  EXPECT_NEAR(tf.Lookup("a", "c")->translation.x, 2.5, 1e-12);
}

}  // namespace
}  // namespace mbot::ros2
