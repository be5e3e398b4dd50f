// What the camera tells the robot about the tags in one frame: detection (the reference detector),
// the pose of each accepted tag in the camera frame (tag_pose.hpp) and, through the camera's
// mounting pose, in the robot frame. Tags whose id is not one of the configured ones are ignored
// and counted.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "mbot/vision/apriltag_detector.hpp"
#include "mbot/vision/tag_pose.hpp"

namespace mbot::vision {

// Where the camera sits on the robot: its optical centre in the robot frame (x forward, y left, z
// up, metres from the point between the wheels on the floor) and its orientation as roll, pitch and
// yaw (radians) away from a camera looking straight ahead (optical axis along +x, image right along
// −y, image down along −z). A positive pitch tilts the camera down.
struct CameraMount {
  double x_m = 0.08, y_m = 0.0, z_m = 0.10;
  double roll_rad = 0.0, pitch_rad = 0.0, yaw_rad = 0.0;
  // Camera frame (OpenCV's) → robot frame.
  cv::Matx33d Rotation() const;
  cv::Vec3d Translation() const { return {x_m, y_m, z_m}; }
};

struct TagObserverOptions {
  TagDetectorOptions detector;
  double tag_size_m = 0.054;  // the black square's side (the botlab's crate tags are 54 mm)
  std::vector<int> ids;       // the ids to report (empty: every id the family has)
  TagPoseMethod pose_method = TagPoseMethod::kIppeSquare;
  // The tags are upright on vertical faces (crates): of IPPE's two poses take the upright one when
  // both fit (EstimateTagPose).
  bool upright_tags = false;
  CameraMount mount;
};

struct ObservedTag {
  TagDetection detection;
  TagPose camera;                    // in the camera frame (OpenCV's)
  std::array<double, 4> quaternion;  // of camera.R: w, x, y, z
  cv::Vec3d robot_position;          // the tag's centre in the robot frame [m]
  double robot_bearing_rad = 0.0;    // atan2(y, x) of robot_position
};

class TagObserver {
 public:
  // Throws std::invalid_argument for a non-positive tag size or a bad detector option.
  TagObserver(const TagObserverOptions& options, const CameraIntrinsics& camera);

  // The accepted tags in `image` (8-bit grey or colour), sorted by id.
  std::vector<ObservedTag> Observe(const cv::Mat& image);

  int64_t ignored() const { return ignored_; }  // detections of ids not in options().ids, so far
  const TagObserverOptions& options() const { return options_; }

 private:
  TagObserverOptions options_;
  CameraIntrinsics camera_;
  TagDetector detector_;
  int64_t ignored_ = 0;
};

// The unit quaternion (w, x, y, z, w ≥ 0) of a rotation matrix.
std::array<double, 4> QuaternionOf(const cv::Matx33d& R);

// A tag seen by a camera at `mount`, in the robot frame: its centre, and the heading (about the
// robot's z) its printed face looks towards — the face's outward normal. From the tag's pose in the
// camera frame (OpenCV's): its position and the unit quaternion (w, x, y, z) of its rotation.
struct TagOnRobot {
  cv::Vec3d position;
  double facing_rad = 0.0;
};
TagOnRobot TagInRobotFrame(const CameraMount& mount, const cv::Vec3d& t_camera, const std::array<double, 4>& q_wxyz);

// Intrinsics from a camera.yaml (ReadCameraYaml).
CameraIntrinsics IntrinsicsFromYaml(const std::string& path);

}  // namespace mbot::vision
