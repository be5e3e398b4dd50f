// A tag's pose in the camera frame from its four corners: OpenCV's solvePnP with the square-tag
// solver (IPPE_SQUARE, on the corners with the lens distortion removed by OpenCV), or the reference
// library's own estimator (homography, orthogonal iteration and its ambiguity resolution; it assumes
// an undistorted image, so it gets the undistorted corners too). The tag frame: origin at the tag's
// centre, x to the right and y down the tag as printed, z into it; the camera frame is OpenCV's.
#pragma once

#include <opencv2/core.hpp>

#include "mbot/vision/apriltag_detector.hpp"

namespace mbot::vision {

struct CameraIntrinsics {
  cv::Matx33d K = cv::Matx33d::eye();
  cv::Mat distortion;  // k1 k2 p1 p2 [k3 …] (OpenCV's order); empty: none
};

enum class TagPoseMethod { kIppeSquare, kAprilTagLibrary };
const char* ToString(TagPoseMethod m);

struct TagPose {
  cv::Matx33d R = cv::Matx33d::eye();  // tag frame → camera frame
  cv::Vec3d t;                         // the tag's centre in the camera frame [m]
  double reprojection_error_px = 0.0;  // RMS over the four corners, through the full camera model
};

// Throws std::invalid_argument when tag_size_m is not positive. With `down` (the world's down in
// the camera frame, unit) and IPPE_SQUARE, the tag is known to be upright (printed on a vertical
// face, its y axis pointing down): of IPPE's two poses — a small tag seen face on fits both almost
// equally — the more upright one is taken unless its reprojection error is more than twice the
// other's (and 0.3 px above it).
TagPose EstimateTagPose(const TagDetection& tag, double tag_size_m, const CameraIntrinsics& camera,
                        TagPoseMethod method, const cv::Vec3d* down = nullptr);

// The tag's corners in its own frame, in the order the detector reports them.
std::array<cv::Point3d, 4> TagCornersInTagFrame(double tag_size_m);

}  // namespace mbot::vision
