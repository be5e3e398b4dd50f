#include "mbot/vision/tag_observer.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "mbot/vision/camera_calibration.hpp"

namespace mbot::vision {

cv::Matx33d CameraMount::Rotation() const {
  // A camera looking straight ahead: its z (optical axis) along the robot's x, its x (image right)
  // along −y, its y (image down) along −z.
  const cv::Matx33d ahead(0, 0, 1, -1, 0, 0, 0, -1, 0);
  const double cr = std::cos(roll_rad), sr = std::sin(roll_rad);
  const double cp = std::cos(pitch_rad), sp = std::sin(pitch_rad);
  const double cy = std::cos(yaw_rad), sy = std::sin(yaw_rad);
  const cv::Matx33d Rz(cy, -sy, 0, sy, cy, 0, 0, 0, 1);
  const cv::Matx33d Ry(cp, 0, sp, 0, 1, 0, -sp, 0, cp);  // a positive pitch turns +x towards −z: down
  const cv::Matx33d Rx(1, 0, 0, 0, cr, -sr, 0, sr, cr);
  return Rz * Ry * Rx * ahead;
}

TagOnRobot TagInRobotFrame(const CameraMount& mount, const cv::Vec3d& t_camera, const std::array<double, 4>& q) {
  const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  const double w = q[0] / n, x = q[1] / n, y = q[2] / n, z = q[3] / n;
  // The tag's z axis (into the printed face) in the camera frame: the rotation's third column.
  const cv::Vec3d into(2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y));
  const cv::Matx33d R = mount.Rotation();
  const cv::Vec3d d = R * into;
  return {R * t_camera + mount.Translation(), std::atan2(-d[1], -d[0])};
}

std::array<double, 4> QuaternionOf(const cv::Matx33d& R) {
  // Shepperd's method: the largest of the four squares decides, so no division is near zero.
  const double t = R(0, 0) + R(1, 1) + R(2, 2);
  std::array<double, 4> q;  // w, x, y, z
  if (t > 0) {
    const double s = 2.0 * std::sqrt(1.0 + t);
    q = {0.25 * s, (R(2, 1) - R(1, 2)) / s, (R(0, 2) - R(2, 0)) / s, (R(1, 0) - R(0, 1)) / s};
  } else if (R(0, 0) > R(1, 1) && R(0, 0) > R(2, 2)) {
    const double s = 2.0 * std::sqrt(1.0 + R(0, 0) - R(1, 1) - R(2, 2));
    q = {(R(2, 1) - R(1, 2)) / s, 0.25 * s, (R(0, 1) + R(1, 0)) / s, (R(0, 2) + R(2, 0)) / s};
  } else if (R(1, 1) > R(2, 2)) {
    const double s = 2.0 * std::sqrt(1.0 + R(1, 1) - R(0, 0) - R(2, 2));
    q = {(R(0, 2) - R(2, 0)) / s, (R(0, 1) + R(1, 0)) / s, 0.25 * s, (R(1, 2) + R(2, 1)) / s};
  } else {
    const double s = 2.0 * std::sqrt(1.0 + R(2, 2) - R(0, 0) - R(1, 1));
    q = {(R(1, 0) - R(0, 1)) / s, (R(0, 2) + R(2, 0)) / s, (R(1, 2) + R(2, 1)) / s, 0.25 * s};
  }
  const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  const double sign = q[0] < 0 ? -1.0 : 1.0;
  for (double& v : q) v *= sign / n;
  return q;
}

CameraIntrinsics IntrinsicsFromYaml(const std::string& path) {
  const CalibrationResult r = ReadCameraYaml(path);
  CameraIntrinsics c;
  cv::Mat k;
  r.camera_matrix.convertTo(k, CV_64F);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) c.K(i, j) = k.at<double>(i, j);  // ReadCameraYaml checked the 3 × 3 size
  r.distortion.convertTo(c.distortion, CV_64F);
  return c;
}

TagObserver::TagObserver(const TagObserverOptions& options, const CameraIntrinsics& camera)
    : options_(options), camera_(camera), detector_(options.detector) {
  if (!(options.tag_size_m > 0.0)) throw std::invalid_argument("tag observer: tag_size_m must be > 0");
}

std::vector<ObservedTag> TagObserver::Observe(const cv::Mat& image) {
  std::vector<ObservedTag> out;
  const cv::Matx33d mount_R = options_.mount.Rotation();
  const cv::Vec3d mount_t = options_.mount.Translation();
  const cv::Vec3d down = mount_R.t() * cv::Vec3d(0, 0, -1);  // the world's down in the camera frame
  for (const TagDetection& d : detector_.Detect(image)) {
    const std::vector<int>& ids = options_.ids;
    if (!ids.empty() && std::find(ids.begin(), ids.end(), d.id) == ids.end()) {
      ++ignored_;
      continue;
    }
    ObservedTag t;
    t.detection = d;
    t.camera =
        EstimateTagPose(d, options_.tag_size_m, camera_, options_.pose_method, options_.upright_tags ? &down : nullptr);
    t.quaternion = QuaternionOf(t.camera.R);
    t.robot_position = mount_R * t.camera.t + mount_t;
    t.robot_bearing_rad = std::atan2(t.robot_position[1], t.robot_position[0]);
    out.push_back(t);
  }
  return out;
}

}  // namespace mbot::vision
