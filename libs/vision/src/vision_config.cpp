#include "mbot/vision/vision_config.hpp"

#include <cmath>
#include <cstdlib>

#include "mbot/common/config.hpp"

namespace mbot::vision {

TagDetectorOptions ParseTagDetectorOptions(config::Section& s, const TagDetectorOptions& d) {
  TagDetectorOptions o = d;
  o.family = s.GetChoice("family", d.family, TagFamilies(), "tag family");
  o.max_bits_corrected = static_cast<int>(
      s.GetInt("max_bits_corrected", d.max_bits_corrected,
               "bit errors the decoder corrects (-1: 2, or 1 for a family of over 10,000 codes)", -1, 3));
  o.decimate = s.GetDouble("decimate", d.decimate, "find quads on an image this much smaller", 1.0, 16.0);
  o.blur_sigma = s.GetDouble("blur_sigma", d.blur_sigma, "Gaussian blur before quads (0: none) [px]", 0.0, 10.0);
  o.refine_edges = s.GetBool("refine_edges", d.refine_edges, "snap quad edges to strong gradients");
  o.decode_sharpening =
      s.GetDouble("decode_sharpening", d.decode_sharpening, "sharpening of the decoded bits", 0.0, 10.0);
  o.threads = static_cast<int>(s.GetInt("threads", d.threads, "detector threads", 1, 64));
  return o;
}

CameraMount ParseCameraMount(config::Section& s, const CameraMount& d) {
  CameraMount m;
  const double deg = M_PI / 180.0;
  m.x_m = s.GetDouble("camera_x_m", d.x_m, "camera on the robot: ahead of the wheel axle centre [m]", -10, 10);
  m.y_m = s.GetDouble("camera_y_m", d.y_m, "camera on the robot: to the left [m]", -10, 10);
  m.z_m = s.GetDouble("camera_z_m", d.z_m, "camera on the robot: above the floor [m]", -10, 10);
  m.roll_rad = deg * s.GetDouble("camera_roll_deg", d.roll_rad / deg, "camera roll about its axis [deg]", -180, 180);
  m.pitch_rad = deg * s.GetDouble("camera_pitch_deg", d.pitch_rad / deg, "camera tilt, down positive [deg]", -90, 90);
  m.yaw_rad = deg * s.GetDouble("camera_yaw_deg", d.yaw_rad / deg, "camera turned left of ahead [deg]", -180, 180);
  return m;
}

TagObserverOptions ParseTagObserverOptions(config::Section& s, const TagObserverOptions& d) {
  TagObserverOptions o = d;
  o.detector = ParseTagDetectorOptions(s, d.detector);
  o.tag_size_m = s.GetDouble("tag_size_m", d.tag_size_m, "side of the tag's black square [m]", 1e-3, 10.0);
  std::vector<std::string> def_ids;
  for (int id : d.ids) def_ids.push_back(std::to_string(id));
  o.ids.clear();
  for (const std::string& id : s.GetList("tag_ids", def_ids,
                                         "the tag ids to report (empty: all); others are "
                                         "ignored and counted")) {
    char* end = nullptr;
    const long v = std::strtol(id.c_str(), &end, 10);
    if (id.empty() || *end != '\0' || v < 0 || v > 100000) s.Fail("tag_ids", "'" + id + "' is not a tag id");
    o.ids.push_back(static_cast<int>(v));
  }
  const std::string method = s.GetChoice(
      "pose_method", d.pose_method == TagPoseMethod::kIppeSquare ? "ippe_square" : "apriltag",
      {"ippe_square", "apriltag"}, "tag pose: OpenCV's solvePnP IPPE_SQUARE or the reference library's estimator");
  o.pose_method = method == "ippe_square" ? TagPoseMethod::kIppeSquare : TagPoseMethod::kAprilTagLibrary;
  o.upright_tags = s.GetBool("upright_tags", d.upright_tags,
                             "the tags are upright on vertical faces: of the two poses that fit a small tag seen "
                             "face on, take the upright one");
  o.mount = ParseCameraMount(s, d.mount);
  return o;
}

}  // namespace mbot::vision
