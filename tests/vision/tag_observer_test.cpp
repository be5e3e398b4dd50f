// The tag observer: a tag rendered at a known place in front of a mounted camera comes out at that
// place in the robot frame; quaternions of any rotation round-trip; ids outside the list are
// ignored and counted.
#include "mbot/vision/tag_observer.hpp"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "render_tags.hpp"

namespace mbot::vision {
namespace {

const cv::Matx33d kK(530, 0, 320, 0, 530, 240, 0, 0, 1);
constexpr double kTagSize = 0.054;

cv::Mat RenderTag(int id, const cv::Matx33d& R, const cv::Vec3d& t) { return test::RenderTag(kK, kTagSize, id, R, t); }

cv::Matx33d FromQuaternion(const std::array<double, 4>& q) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  return cv::Matx33d(1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y), 2 * (x * y + w * z),
                     1 - 2 * (x * x + z * z), 2 * (y * z - w * x), 2 * (x * z - w * y), 2 * (y * z + w * x),
                     1 - 2 * (x * x + y * y));
}

TEST(TagObserverTest, QuaternionsRoundTripEveryRotation) {
  std::mt19937 rng(4);
  std::normal_distribution<double> n(0.0, 1.5);
  std::vector<cv::Vec3d> rvecs = {
      {0, 0, 0}, {M_PI, 0, 0}, {0, M_PI, 0}, {0, 0, M_PI}, {M_PI / std::sqrt(2.0), M_PI / std::sqrt(2.0), 0}};
  for (int k = 0; k < 200; ++k) rvecs.push_back({n(rng), n(rng), n(rng)});
  for (const cv::Vec3d& rv : rvecs) {
    cv::Matx33d R;
    cv::Rodrigues(rv, R);
    const std::array<double, 4> q = QuaternionOf(R);
    EXPECT_NEAR(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3], 1.0, 1e-12);
    EXPECT_GE(q[0], 0.0);
    EXPECT_LT(cv::norm(FromQuaternion(q) - R), 1e-9) << rv;
  }
}

// A camera 8 cm ahead of the axle centre, 10 cm up, tilted 15° down: a tag standing on the floor
// 0.5 m ahead and 0.1 m to the left, facing the robot, is found there in the robot frame.
TEST(TagObserverTest, TagsLandWhereTheyAreInTheRobotFrame) {
  TagObserverOptions o;
  o.detector.decimate = 1.0;
  o.tag_size_m = kTagSize;
  o.mount.pitch_rad = 15.0 * M_PI / 180.0;
  CameraIntrinsics camera;
  camera.K = kK;
  TagObserver observer(o, camera);
  const cv::Matx33d Rc = o.mount.Rotation();  // camera → robot
  const cv::Vec3d tc = o.mount.Translation();
  for (const cv::Vec3d& where : {cv::Vec3d{0.5, 0.1, 0.05}, cv::Vec3d{0.35, -0.08, 0.04}, cv::Vec3d{0.8, 0.0, 0.06}}) {
    // The tag's frame in the robot frame: facing −x (towards the robot), its x along −y, its y down.
    const cv::Matx33d tag_in_robot(0, 0, -1, -1, 0, 0, 0, -1, 0);
    const cv::Matx33d R = Rc.t() * tag_in_robot;
    const cv::Vec3d t = Rc.t() * (where - tc);
    const std::vector<ObservedTag> seen = observer.Observe(RenderTag(7, R, t));
    ASSERT_EQ(seen.size(), 1u) << where;
    EXPECT_EQ(seen[0].detection.id, 7);
    EXPECT_LT(cv::norm(seen[0].robot_position - where), 0.01) << where << " got " << seen[0].robot_position;
    EXPECT_NEAR(seen[0].robot_bearing_rad, std::atan2(where[1], where[0]), 0.02);
    EXPECT_LT(cv::norm(FromQuaternion(seen[0].quaternion) - seen[0].camera.R), 1e-9);
  }
}

// The mounting pose's conventions, independently of the renderer: the optical axis of a camera
// pitched down 15° runs ahead and down; image right is the robot's right; a yaw turns it left.
TEST(TagObserverTest, MountConventions) {
  CameraMount m;
  m.pitch_rad = 15.0 * M_PI / 180.0;
  const cv::Vec3d ahead = m.Rotation() * cv::Vec3d(0, 0, 1.0) + m.Translation();
  EXPECT_NEAR(ahead[0], 0.08 + std::cos(m.pitch_rad), 1e-12);
  EXPECT_NEAR(ahead[1], 0.0, 1e-12);
  EXPECT_NEAR(ahead[2], 0.10 - std::sin(m.pitch_rad), 1e-12);
  const cv::Vec3d right = m.Rotation() * cv::Vec3d(1.0, 0, 0);
  EXPECT_NEAR(right[1], -1.0, 1e-12);
  m = CameraMount{};
  m.yaw_rad = M_PI / 2;
  const cv::Vec3d left = m.Rotation() * cv::Vec3d(0, 0, 1.0);
  EXPECT_NEAR(left[1], 1.0, 1e-12);
}

TEST(TagObserverTest, OtherIdsAreIgnoredAndCounted) {
  TagObserverOptions o;
  o.detector.decimate = 1.0;
  o.tag_size_m = kTagSize;
  o.ids = {1, 2, 3};
  CameraIntrinsics camera;
  camera.K = kK;
  TagObserver observer(o, camera);
  EXPECT_TRUE(observer.Observe(RenderTag(7, cv::Matx33d::eye(), {0, 0, 0.4})).empty());
  EXPECT_EQ(observer.ignored(), 1);
  EXPECT_EQ(observer.Observe(RenderTag(2, cv::Matx33d::eye(), {0, 0, 0.4})).size(), 1u);
  o.tag_size_m = 0;
  EXPECT_THROW(TagObserver(o, camera), std::invalid_argument);
}

}  // namespace
}  // namespace mbot::vision
