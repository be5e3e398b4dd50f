#include "mbot/vision/tag_pose.hpp"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "render_tags.hpp"

namespace mbot::vision {
namespace {

const cv::Matx33d kK(600, 0, 320, 0, 600, 240, 0, 0, 1);
constexpr double kTagSize = 0.10;  // the black square's side [m]

// tag36h11 id 3 seen by kK at the pose (R, t) of its tag frame in the camera frame.
cv::Mat RenderTag(const cv::Matx33d& R, const cv::Vec3d& t) { return test::RenderTag(kK, kTagSize, 3, R, t); }

double AngleDeg(const cv::Matx33d& a, const cv::Matx33d& b) {
  cv::Vec3d r;
  cv::Rodrigues(a.t() * b, r);
  return cv::norm(r) * 180.0 / M_PI;
}

// Both estimators recover rendered poses; the figures per method are recorded (BENCHMARKS.md).
TEST(TagPoseTest, BothEstimatorsRecoverRenderedPoses) {
  const cv::Vec3d rotations[] = {{0, 0, 0},          {0.3, 0, 0},      {0, -0.4, 0},     {0.2, 0.3, 0.5},
                                 {-0.35, 0.2, -1.0}, {0.1, -0.5, 2.0}, {0.45, 0.1, 3.0}, {-0.2, -0.3, -2.5}};
  const cv::Vec3d positions[] = {{0.0, 0.0, 0.5}, {0.08, -0.05, 0.7}, {-0.1, 0.06, 0.9}};
  CameraIntrinsics camera;
  camera.K = kK;
  TagDetectorOptions o;
  o.decimate = 1.0;
  const TagDetector detector(o);
  for (TagPoseMethod m : {TagPoseMethod::kIppeSquare, TagPoseMethod::kAprilTagLibrary}) {
    double worst_t = 0, worst_r = 0, sum_t = 0, sum_r = 0;
    int n = 0;
    for (const cv::Vec3d& rv : rotations) {
      for (const cv::Vec3d& t : positions) {
        cv::Matx33d R;
        cv::Rodrigues(rv, R);
        const std::vector<TagDetection> found = detector.Detect(RenderTag(R, t));
        ASSERT_EQ(found.size(), 1u) << "rotation " << rv << " position " << t;
        ASSERT_EQ(found[0].id, 3);
        const TagPose p = EstimateTagPose(found[0], kTagSize, camera, m);
        const double et = cv::norm(p.t - t), er = AngleDeg(p.R, R);
        EXPECT_LT(et, 0.01) << ToString(m) << " rotation " << rv << " position " << t << " got " << p.t;
        EXPECT_LT(er, 3.0) << ToString(m) << " rotation " << rv << " position " << t;
        EXPECT_LT(p.reprojection_error_px, 1.0);
        worst_t = std::max(worst_t, et), worst_r = std::max(worst_r, er), sum_t += et, sum_r += er, ++n;
      }
    }
    const std::string k = ToString(m);
    RecordProperty(k + "_mean_t_mm", std::to_string(1000 * sum_t / n));
    RecordProperty(k + "_max_t_mm", std::to_string(1000 * worst_t));
    RecordProperty(k + "_mean_rot_deg", std::to_string(sum_r / n));
    RecordProperty(k + "_max_rot_deg", std::to_string(worst_r));
  }
}

TEST(TagPoseTest, CornersInTheTagFrameAndBadSize) {
  const auto c = TagCornersInTagFrame(0.2);
  EXPECT_EQ(c[0], cv::Point3d(-0.1, 0.1, 0));
  EXPECT_EQ(c[2], cv::Point3d(0.1, -0.1, 0));
  EXPECT_THROW(EstimateTagPose(TagDetection{}, 0.0, CameraIntrinsics{}, TagPoseMethod::kIppeSquare),
               std::invalid_argument);
}

}  // namespace
}  // namespace mbot::vision
