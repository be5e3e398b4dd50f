#include "mbot/vision/tag_pose.hpp"

#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include <opencv2/calib3d.hpp>

extern "C" {
#include <apriltag.h>
#include <apriltag_pose.h>
}

namespace mbot::vision {
namespace {

// The detector reports the corners starting at the tag's bottom-left (as printed) and going
// counter-clockwise in the image: bottom-left, bottom-right, top-right, top-left. In the tag frame
// (x right, y down the printed tag, z into it) with half size h: (-h, h), (h, h), (h, -h), (-h, -h).
constexpr double kCornerSigns[4][2] = {{-1, 1}, {1, 1}, {1, -1}, {-1, -1}};

std::vector<cv::Point2d> Undistorted(const TagDetection& tag, const CameraIntrinsics& camera) {
  std::vector<cv::Point2d> in(tag.corners.begin(), tag.corners.end()), out;
  if (camera.distortion.empty()) return in;
  cv::undistortPoints(in, out, camera.K, camera.distortion, cv::noArray(), camera.K);
  return out;
}

// A matd_t as the library's public header lays it out (a flexible array member), for the matrices
// it reads and the ones it returns (it allocates those with malloc; libapriltag does not export
// matd_destroy, so they are freed here with free).
matd_t* NewMatd(int rows, int cols) {
  auto* m = static_cast<matd_t*>(std::calloc(1, sizeof(matd_t) + sizeof(double) * rows * cols));
  if (!m) throw std::bad_alloc();
  m->nrows = rows, m->ncols = cols;
  return m;
}

}  // namespace

const char* ToString(TagPoseMethod m) { return m == TagPoseMethod::kIppeSquare ? "ippe_square" : "apriltag_library"; }

std::array<cv::Point3d, 4> TagCornersInTagFrame(double tag_size_m) {
  const double h = tag_size_m / 2;
  std::array<cv::Point3d, 4> p;
  for (int k = 0; k < 4; ++k) p[k] = {kCornerSigns[k][0] * h, kCornerSigns[k][1] * h, 0.0};
  return p;
}

TagPose EstimateTagPose(const TagDetection& tag, double tag_size_m, const CameraIntrinsics& camera,
                        TagPoseMethod method, const cv::Vec3d* down) {
  if (!(tag_size_m > 0)) throw std::invalid_argument("tag pose: tag size must be positive");
  const std::array<cv::Point3d, 4> object = TagCornersInTagFrame(tag_size_m);
  TagPose pose;
  if (method == TagPoseMethod::kIppeSquare) {
    // IPPE_SQUARE wants the corners as (-h, h), (h, h), (h, -h), (-h, -h): the detector's order.
    std::vector<cv::Point3d> obj(object.begin(), object.end());
    std::vector<cv::Point2d> img(tag.corners.begin(), tag.corners.end());
    std::vector<cv::Mat> rvecs, tvecs;
    cv::Mat errors;
    const int n = cv::solvePnPGeneric(obj, img, camera.K, camera.distortion, rvecs, tvecs, false,
                                      cv::SOLVEPNP_IPPE_SQUARE, cv::noArray(), cv::noArray(), errors);
    int pick = 0;  // IPPE sorts its two solutions by reprojection error
    if (down && n == 2) {
      auto uprightness = [&](int k) {
        cv::Matx33d R;
        cv::Rodrigues(rvecs[k], R);
        return (R * cv::Vec3d(0, 1, 0)).dot(*down);  // the tag's y axis against the world's down
      };
      const double e0 = errors.at<double>(0), e1 = errors.at<double>(1);
      if (uprightness(1) > uprightness(0) && (e1 <= 2 * e0 || e1 <= e0 + 0.3)) pick = 1;
    }
    cv::Rodrigues(rvecs[pick], pose.R);
    pose.t = cv::Vec3d(tvecs[pick].at<double>(0), tvecs[pick].at<double>(1), tvecs[pick].at<double>(2));
  } else {
    const std::vector<cv::Point2d> corners = Undistorted(tag, camera);
    apriltag_detection_t det{};
    det.id = tag.id;
    for (int k = 0; k < 4; ++k) det.p[k][0] = corners[k].x, det.p[k][1] = corners[k].y;
    det.c[0] = tag.center.x, det.c[1] = tag.center.y;
    // The library starts from the homography of the square (-1..1)² to the pixels: recomputed from
    // the (undistorted) corners with the library's own corner order.
    std::vector<cv::Point2d> square = {{-1, 1}, {1, 1}, {1, -1}, {-1, -1}};
    const cv::Mat H = cv::findHomography(square, corners);
    det.H = NewMatd(3, 3);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) det.H->data[r * 3 + c] = H.at<double>(r, c);
    }
    apriltag_detection_info_t info{&det, tag_size_m, camera.K(0, 0), camera.K(1, 1), camera.K(0, 2), camera.K(1, 2)};
    apriltag_pose_t lib{nullptr, nullptr};
    estimate_tag_pose(&info, &lib);
    std::free(det.H);
    cv::Matx33d R_lib;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) R_lib(r, c) = lib.R->data[r * 3 + c];
    }
    pose.t = {lib.t->data[0], lib.t->data[1], lib.t->data[2]};
    std::free(lib.R);
    std::free(lib.t);
    pose.R = R_lib;  // given the corners in this order, the library's tag frame is ours
  }
  // RMS reprojection error through the full camera model.
  std::vector<cv::Point3d> obj(object.begin(), object.end());
  std::vector<cv::Point2d> projected;
  cv::Vec3d rvec;
  cv::Rodrigues(pose.R, rvec);
  cv::projectPoints(obj, rvec, pose.t, camera.K, camera.distortion, projected);
  double sum2 = 0;
  for (int k = 0; k < 4; ++k) sum2 += std::pow(cv::norm(projected[k] - tag.corners[k]), 2);
  pose.reprojection_error_px = std::sqrt(sum2 / 4);
  return pose;
}

}  // namespace mbot::vision
