// The ROS 2 messages the MBot's generation speaks (Jazzy; written from the public .msg files of
// common_interfaces and geometry2), as plain structs, and their CDR encoding. Field order and types
// follow the .msg files exactly; each Decode throws CdrError naming the field and offset of what
// does not fit.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "mbot/ros2/cdr.hpp"

namespace mbot::ros2 {

struct Time {  // builtin_interfaces/Time
  int32_t sec = 0;
  uint32_t nanosec = 0;
};
struct Header {  // std_msgs/Header
  Time stamp;
  std::string frame_id;
};
struct Vector3 {  // geometry_msgs/Vector3 (and Point: the same three float64)
  double x = 0, y = 0, z = 0;
};
struct Quaternion {  // geometry_msgs/Quaternion
  double x = 0, y = 0, z = 0, w = 1;
};
struct Pose {  // geometry_msgs/Pose
  Vector3 position;
  Quaternion orientation;
};
struct Twist {  // geometry_msgs/Twist
  Vector3 linear, angular;
};
struct Transform {  // geometry_msgs/Transform
  Vector3 translation;
  Quaternion rotation;
};
struct TransformStamped {  // geometry_msgs/TransformStamped
  Header header;
  std::string child_frame_id;
  Transform transform;
};
struct TFMessage {  // tf2_msgs/TFMessage
  std::vector<TransformStamped> transforms;
};
struct LaserScan {  // sensor_msgs/LaserScan
  Header header;
  float angle_min = 0, angle_max = 0, angle_increment = 0;
  float time_increment = 0, scan_time = 0;
  float range_min = 0, range_max = 0;
  std::vector<float> ranges, intensities;
};
struct Odometry {  // nav_msgs/Odometry
  Header header;
  std::string child_frame_id;
  Pose pose;
  std::array<double, 36> pose_covariance{};
  Twist twist;
  std::array<double, 36> twist_covariance{};
};
struct Imu {  // sensor_msgs/Imu
  Header header;
  Quaternion orientation;
  std::array<double, 9> orientation_covariance{};
  Vector3 angular_velocity;
  std::array<double, 9> angular_velocity_covariance{};
  Vector3 linear_acceleration;
  std::array<double, 9> linear_acceleration_covariance{};
};

struct PoseStamped {  // geometry_msgs/PoseStamped
  Header header;
  Pose pose;
};
struct PoseWithCovarianceStamped {  // geometry_msgs/PoseWithCovarianceStamped (amcl's pose)
  Header header;
  Pose pose;
  std::array<double, 36> covariance{};
};
struct PoseArray {  // geometry_msgs/PoseArray
  Header header;
  std::vector<Pose> poses;
};
struct Path {  // nav_msgs/Path
  Header header;
  std::vector<PoseStamped> poses;
};
struct MapMetaData {  // nav_msgs/MapMetaData
  Time map_load_time;
  float resolution = 0;
  uint32_t width = 0, height = 0;
  Pose origin;
};
struct OccupancyGrid {  // nav_msgs/OccupancyGrid: row-major from the origin; 0-100, -1 unknown
  Header header;
  MapMetaData info;
  std::vector<int8_t> data;
};

struct String {  // std_msgs/String
  std::string data;
};
struct Encoders {  // mbot_interfaces/Encoders (the MBot's firmware): [0] left, [1] right, [2] unused
  Time stamp;
  std::array<int64_t, 3> ticks{};
  std::array<int32_t, 3> delta_ticks{};
  int32_t delta_time = 0;  // [µs]
};
struct MotorVelocity {  // mbot_interfaces/MotorVelocity (the MBot's firmware): [0] left, [1] right [rad/s]
  std::array<float, 3> velocity{};
};
struct ColorRGBA {  // std_msgs/ColorRGBA
  float r = 0, g = 0, b = 0, a = 0;
};
struct Marker {  // visualization_msgs/Marker (Jazzy: with texture, uv_coordinates and mesh_file)
  Header header;
  std::string ns;
  int32_t id = 0, type = 0, action = 0;
  Pose pose;
  Vector3 scale;
  ColorRGBA color;
  Time lifetime;  // builtin_interfaces/Duration: the same two fields
  bool frame_locked = false;
  std::vector<Vector3> points;
  std::vector<ColorRGBA> colors;
  std::string text;  // texture_resource, texture, uv_coordinates, mesh_resource, mesh_file: empty
  bool mesh_use_embedded_materials = false;
  static constexpr int32_t kPoints = 8, kAdd = 0, kDeleteAll = 3;
};
struct MarkerArray {  // visualization_msgs/MarkerArray
  std::vector<Marker> markers;
};

struct AprilTagDetection {  // apriltag_msgs/AprilTagDetection (apriltag_ros: what the MBot's camera publishes)
  std::string family;
  int32_t id = 0, hamming = 0;
  float goodness = 0, decision_margin = 0;
  std::array<double, 2> centre{};      // apriltag_msgs/Point centre: x, y [px]
  std::array<double, 8> corners{};     // apriltag_msgs/Point[4] corners
  std::array<double, 9> homography{};  // row-major
};
struct AprilTagDetectionArray {  // apriltag_msgs/AprilTagDetectionArray
  Header header;
  std::vector<AprilTagDetection> detections;
};

// The ROS 2 type names ("sensor_msgs/msg/LaserScan"), as rosbag2 and the DDS layer name them.
inline constexpr const char* kLaserScanType = "sensor_msgs/msg/LaserScan";
inline constexpr const char* kOdometryType = "nav_msgs/msg/Odometry";
inline constexpr const char* kImuType = "sensor_msgs/msg/Imu";
inline constexpr const char* kTwistType = "geometry_msgs/msg/Twist";
inline constexpr const char* kTFMessageType = "tf2_msgs/msg/TFMessage";
inline constexpr const char* kPoseStampedType = "geometry_msgs/msg/PoseStamped";
inline constexpr const char* kPoseWithCovarianceStampedType = "geometry_msgs/msg/PoseWithCovarianceStamped";
inline constexpr const char* kPoseArrayType = "geometry_msgs/msg/PoseArray";
inline constexpr const char* kPathType = "nav_msgs/msg/Path";
inline constexpr const char* kOccupancyGridType = "nav_msgs/msg/OccupancyGrid";
inline constexpr const char* kStringType = "std_msgs/msg/String";
inline constexpr const char* kEncodersType = "mbot_interfaces/msg/Encoders";
inline constexpr const char* kMotorVelocityType = "mbot_interfaces/msg/MotorVelocity";
inline constexpr const char* kMarkerArrayType = "visualization_msgs/msg/MarkerArray";
inline constexpr const char* kAprilTagDetectionArrayType = "apriltag_msgs/msg/AprilTagDetectionArray";
// std_srvs/srv/Trigger (the MBot's /reset_odometry): its request and response as they travel on DDS,
// on rq/<service>Request and rr/<service>Reply.
inline constexpr const char* kTriggerRequestType = "std_srvs/srv/Trigger_Request";
inline constexpr const char* kTriggerResponseType = "std_srvs/srv/Trigger_Response";

struct TriggerResponse {  // std_srvs/Trigger's response
  bool success = false;
  std::string message;
};
// rmw_cyclonedds_cpp puts this request header (the client's writer handle, a sequence number) in
// front of every request and response; rmw_fastrtps and micro-ROS carry the request's identity in
// the RTPS message instead, and their payloads are the message alone.
struct ServiceHeader {
  uint64_t guid = 0;
  int64_t sequence = 0;
};
// Trigger's request (empty: one uint8 placeholder), with rmw_cyclonedds's header when given.
std::vector<uint8_t> EncodeTriggerRequest(const ServiceHeader* header = nullptr);
// Checks a request; true when it carried rmw_cyclonedds's header (then `header` holds it). Throws
// CdrError for a payload that is neither form.
bool DecodeTriggerRequest(const uint8_t* data, size_t size, ServiceHeader* header);
std::vector<uint8_t> Encode(const TriggerResponse& m, const ServiceHeader* header = nullptr);
// A response without the header (what the MBot's micro-ROS agent sends).
TriggerResponse DecodeTriggerResponse(const uint8_t* data, size_t size);

// How a payload is serialized: ROS 2's CDR, or ROS 1's (a ROS 1 bag: packed, Header with seq).
enum class Serialization { kCdr, kRos1 };

LaserScan DecodeLaserScan(const uint8_t* data, size_t size, Serialization s = Serialization::kCdr);
Odometry DecodeOdometry(const uint8_t* data, size_t size, Serialization s = Serialization::kCdr);
Imu DecodeImu(const uint8_t* data, size_t size, Serialization s = Serialization::kCdr);
Twist DecodeTwist(const uint8_t* data, size_t size, Serialization s = Serialization::kCdr);
TFMessage DecodeTFMessage(const uint8_t* data, size_t size, Serialization s = Serialization::kCdr);
PoseStamped DecodePoseStamped(const uint8_t* data, size_t size, Serialization s = Serialization::kCdr);
PoseWithCovarianceStamped DecodePoseWithCovarianceStamped(const uint8_t* data, size_t size,
                                                          Serialization s = Serialization::kCdr);
OccupancyGrid DecodeOccupancyGrid(const uint8_t* data, size_t size, Serialization s = Serialization::kCdr);
String DecodeString(const uint8_t* data, size_t size, Serialization s = Serialization::kCdr);
Encoders DecodeEncoders(const uint8_t* data, size_t size, Serialization s = Serialization::kCdr);
MotorVelocity DecodeMotorVelocity(const uint8_t* data, size_t size, Serialization s = Serialization::kCdr);
AprilTagDetectionArray DecodeAprilTagDetectionArray(const uint8_t* data, size_t size,
                                                    Serialization s = Serialization::kCdr);

std::vector<uint8_t> Encode(const LaserScan& m);
std::vector<uint8_t> Encode(const Odometry& m);
std::vector<uint8_t> Encode(const Imu& m);
std::vector<uint8_t> Encode(const Twist& m);
std::vector<uint8_t> Encode(const TFMessage& m);
std::vector<uint8_t> Encode(const PoseStamped& m);
std::vector<uint8_t> Encode(const PoseWithCovarianceStamped& m);
std::vector<uint8_t> Encode(const PoseArray& m);
std::vector<uint8_t> Encode(const Path& m);
std::vector<uint8_t> Encode(const OccupancyGrid& m);
std::vector<uint8_t> Encode(const String& m);
std::vector<uint8_t> Encode(const Encoders& m);
std::vector<uint8_t> Encode(const MotorVelocity& m);
std::vector<uint8_t> Encode(const MarkerArray& m);
std::vector<uint8_t> Encode(const AprilTagDetectionArray& m);

// A planar yaw from a quaternion, and back (the MBot's frames differ by yaw only).
double Yaw(const Quaternion& q);
Quaternion FromYaw(double yaw);

}  // namespace mbot::ros2
