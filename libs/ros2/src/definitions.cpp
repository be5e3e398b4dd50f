#include "mbot/ros2/definitions.hpp"

#include <functional>
#include <map>
#include <set>
#include <stdexcept>

namespace mbot::ros2 {

namespace {

struct Def {
  const char* text;
  std::vector<std::string> uses;  // the types its fields name, "pkg/Type"
};

// The fields of each type, in the order of its .msg file (comments, constants and default values
// left out; every type named in full, as a parser without package context needs).
const std::map<std::string, Def>& Defs() {
  static const std::map<std::string, Def> defs = {
      {"builtin_interfaces/Time", {"int32 sec\nuint32 nanosec\n", {}}},
      {"std_msgs/Header", {"builtin_interfaces/Time stamp\nstring frame_id\n", {"builtin_interfaces/Time"}}},
      {"geometry_msgs/Vector3", {"float64 x\nfloat64 y\nfloat64 z\n", {}}},
      {"geometry_msgs/Point", {"float64 x\nfloat64 y\nfloat64 z\n", {}}},
      {"geometry_msgs/Quaternion", {"float64 x\nfloat64 y\nfloat64 z\nfloat64 w\n", {}}},
      {"geometry_msgs/Pose",
       {"geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n",
        {"geometry_msgs/Point", "geometry_msgs/Quaternion"}}},
      {"geometry_msgs/PoseWithCovariance",
       {"geometry_msgs/Pose pose\nfloat64[36] covariance\n", {"geometry_msgs/Pose"}}},
      {"geometry_msgs/Twist",
       {"geometry_msgs/Vector3 linear\ngeometry_msgs/Vector3 angular\n", {"geometry_msgs/Vector3"}}},
      {"geometry_msgs/TwistWithCovariance",
       {"geometry_msgs/Twist twist\nfloat64[36] covariance\n", {"geometry_msgs/Twist"}}},
      {"geometry_msgs/Transform",
       {"geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation\n",
        {"geometry_msgs/Vector3", "geometry_msgs/Quaternion"}}},
      {"geometry_msgs/TransformStamped",
       {"std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/Transform transform\n",
        {"std_msgs/Header", "geometry_msgs/Transform"}}},
      {"geometry_msgs/PoseStamped",
       {"std_msgs/Header header\ngeometry_msgs/Pose pose\n", {"std_msgs/Header", "geometry_msgs/Pose"}}},
      {"geometry_msgs/PoseWithCovarianceStamped",
       {"std_msgs/Header header\ngeometry_msgs/PoseWithCovariance pose\n",
        {"std_msgs/Header", "geometry_msgs/PoseWithCovariance"}}},
      {"geometry_msgs/PoseArray",
       {"std_msgs/Header header\ngeometry_msgs/Pose[] poses\n", {"std_msgs/Header", "geometry_msgs/Pose"}}},
      {"tf2_msgs/TFMessage", {"geometry_msgs/TransformStamped[] transforms\n", {"geometry_msgs/TransformStamped"}}},
      {"sensor_msgs/LaserScan",
       {"std_msgs/Header header\nfloat32 angle_min\nfloat32 angle_max\nfloat32 angle_increment\n"
        "float32 time_increment\nfloat32 scan_time\nfloat32 range_min\nfloat32 range_max\nfloat32[] ranges\n"
        "float32[] intensities\n",
        {"std_msgs/Header"}}},
      {"sensor_msgs/Imu",
       {"std_msgs/Header header\ngeometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance\n"
        "geometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\n"
        "geometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance\n",
        {"std_msgs/Header", "geometry_msgs/Quaternion", "geometry_msgs/Vector3"}}},
      {"nav_msgs/Odometry",
       {"std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance pose\n"
        "geometry_msgs/TwistWithCovariance twist\n",
        {"std_msgs/Header", "geometry_msgs/PoseWithCovariance", "geometry_msgs/TwistWithCovariance"}}},
      {"nav_msgs/MapMetaData",
       {"builtin_interfaces/Time map_load_time\nfloat32 resolution\nuint32 width\nuint32 height\n"
        "geometry_msgs/Pose origin\n",
        {"builtin_interfaces/Time", "geometry_msgs/Pose"}}},
      {"nav_msgs/OccupancyGrid",
       {"std_msgs/Header header\nnav_msgs/MapMetaData info\nint8[] data\n",
        {"std_msgs/Header", "nav_msgs/MapMetaData"}}},
      {"std_msgs/String", {"string data\n", {}}},
      {"std_msgs/ColorRGBA", {"float32 r\nfloat32 g\nfloat32 b\nfloat32 a\n", {}}},
      {"builtin_interfaces/Duration", {"int32 sec\nuint32 nanosec\n", {}}},
      {"mbot_interfaces/Encoders",
       {"builtin_interfaces/Time stamp\nint64[3] ticks\nint32[3] delta_ticks\nint32 delta_time\n",
        {"builtin_interfaces/Time"}}},
      {"mbot_interfaces/MotorVelocity", {"float32[3] velocity\n", {}}},
      // apriltag_ros's detections (apriltag_msgs 2.0, as Jazzy ships it)
      {"apriltag_msgs/Point", {"float64 x\nfloat64 y\n", {}}},
      {"apriltag_msgs/AprilTagDetection",
       {"string family\nint32 id\nint32 hamming\nfloat32 goodness\nfloat32 decision_margin\n"
        "apriltag_msgs/Point centre\napriltag_msgs/Point[4] corners\nfloat64[9] homography\n",
        {"apriltag_msgs/Point"}}},
      {"apriltag_msgs/AprilTagDetectionArray",
       {"std_msgs/Header header\napriltag_msgs/AprilTagDetection[] detections\n",
        {"std_msgs/Header", "apriltag_msgs/AprilTagDetection"}}},
      {"sensor_msgs/CompressedImage", {"std_msgs/Header header\nstring format\nuint8[] data\n", {"std_msgs/Header"}}},
      {"visualization_msgs/UVCoordinate", {"float32 u\nfloat32 v\n", {}}},
      {"visualization_msgs/MeshFile", {"string filename\nuint8[] data\n", {}}},
      {"visualization_msgs/Marker",
       {"std_msgs/Header header\nstring ns\nint32 id\nint32 type\nint32 action\ngeometry_msgs/Pose pose\n"
        "geometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\nbuiltin_interfaces/Duration lifetime\n"
        "bool frame_locked\ngeometry_msgs/Point[] points\nstd_msgs/ColorRGBA[] colors\nstring texture_resource\n"
        "sensor_msgs/CompressedImage texture\nvisualization_msgs/UVCoordinate[] uv_coordinates\nstring text\n"
        "string mesh_resource\nvisualization_msgs/MeshFile mesh_file\nbool mesh_use_embedded_materials\n",
        {"std_msgs/Header", "geometry_msgs/Pose", "geometry_msgs/Vector3", "std_msgs/ColorRGBA",
         "builtin_interfaces/Duration", "geometry_msgs/Point", "sensor_msgs/CompressedImage",
         "visualization_msgs/UVCoordinate", "visualization_msgs/MeshFile"}}},
      {"visualization_msgs/MarkerArray", {"visualization_msgs/Marker[] markers\n", {"visualization_msgs/Marker"}}},
      {"nav_msgs/Path",
       {"std_msgs/Header header\ngeometry_msgs/PoseStamped[] poses\n",
        {"std_msgs/Header", "geometry_msgs/PoseStamped"}}},
  };
  return defs;
}

// "sensor_msgs/msg/LaserScan" → "sensor_msgs/LaserScan".
std::string Short(const std::string& type) {
  const size_t p = type.find("/msg/");
  return p == std::string::npos ? type : type.substr(0, p) + "/" + type.substr(p + 5);
}

}  // namespace

std::string Definition(const std::string& type) {
  const auto& defs = Defs();
  const std::string top = Short(type);
  std::string text = defs.at(top).text;
  std::set<std::string> done = {top};
  std::function<void(const std::string&)> add = [&](const std::string& name) {
    for (const std::string& used : defs.at(name).uses) {
      if (!done.insert(used).second) continue;
      text += std::string(80, '=') + "\nMSG: " + used + "\n" + defs.at(used).text;
      add(used);
    }
  };
  add(top);
  return text;
}

std::vector<std::string> DefinedTypes() {
  std::vector<std::string> out;
  for (const auto& [name, def] : Defs()) {
    const size_t slash = name.find('/');
    out.push_back(name.substr(0, slash) + "/msg/" + name.substr(slash + 1));
  }
  return out;
}

}  // namespace mbot::ros2
