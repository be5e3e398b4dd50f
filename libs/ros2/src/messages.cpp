#include "mbot/ros2/messages.hpp"

#include <cmath>

namespace mbot::ros2 {

namespace {

CdrReader Reader(const uint8_t* data, size_t size, Serialization s) {
  return s == Serialization::kRos1 ? CdrReader(CdrReader::Ros1{}, data, size) : CdrReader(data, size);
}

Header ReadHeader(CdrReader& r) {
  Header h;
  if (r.ros1()) r.U32("header.seq");  // ROS 1's Header starts with a sequence number
  h.stamp.sec = r.I32("header.stamp.sec");
  h.stamp.nanosec = r.U32("header.stamp.nanosec");
  h.frame_id = r.String("header.frame_id");
  return h;
}
void WriteHeader(CdrWriter& w, const Header& h) {
  w.I32(h.stamp.sec);
  w.U32(h.stamp.nanosec);
  w.String(h.frame_id);
}
Vector3 ReadVector3(CdrReader& r, const char* field) {
  Vector3 v;
  v.x = r.F64(field), v.y = r.F64(field), v.z = r.F64(field);
  return v;
}
void WriteVector3(CdrWriter& w, const Vector3& v) { w.F64(v.x), w.F64(v.y), w.F64(v.z); }
Quaternion ReadQuaternion(CdrReader& r, const char* field) {
  Quaternion q;
  q.x = r.F64(field), q.y = r.F64(field), q.z = r.F64(field), q.w = r.F64(field);
  return q;
}
void WriteQuaternion(CdrWriter& w, const Quaternion& q) { w.F64(q.x), w.F64(q.y), w.F64(q.z), w.F64(q.w); }
Twist ReadTwist(CdrReader& r) {
  Twist t;
  t.linear = ReadVector3(r, "twist.linear");
  t.angular = ReadVector3(r, "twist.angular");
  return t;
}
void WriteTwist(CdrWriter& w, const Twist& t) { WriteVector3(w, t.linear), WriteVector3(w, t.angular); }

}  // namespace

LaserScan DecodeLaserScan(const uint8_t* data, size_t size, Serialization serialization) {
  CdrReader r = Reader(data, size, serialization);
  LaserScan m;
  m.header = ReadHeader(r);
  m.angle_min = r.F32("angle_min");
  m.angle_max = r.F32("angle_max");
  m.angle_increment = r.F32("angle_increment");
  m.time_increment = r.F32("time_increment");
  m.scan_time = r.F32("scan_time");
  m.range_min = r.F32("range_min");
  m.range_max = r.F32("range_max");
  m.ranges = r.F32s("ranges");
  m.intensities = r.F32s("intensities");
  return m;
}

Odometry DecodeOdometry(const uint8_t* data, size_t size, Serialization serialization) {
  CdrReader r = Reader(data, size, serialization);
  Odometry m;
  m.header = ReadHeader(r);
  m.child_frame_id = r.String("child_frame_id");
  m.pose.position = ReadVector3(r, "pose.pose.position");
  m.pose.orientation = ReadQuaternion(r, "pose.pose.orientation");
  r.F64Array("pose.covariance", m.pose_covariance.data(), 36);
  m.twist = ReadTwist(r);
  r.F64Array("twist.covariance", m.twist_covariance.data(), 36);
  return m;
}

Imu DecodeImu(const uint8_t* data, size_t size, Serialization serialization) {
  CdrReader r = Reader(data, size, serialization);
  Imu m;
  m.header = ReadHeader(r);
  m.orientation = ReadQuaternion(r, "orientation");
  r.F64Array("orientation_covariance", m.orientation_covariance.data(), 9);
  m.angular_velocity = ReadVector3(r, "angular_velocity");
  r.F64Array("angular_velocity_covariance", m.angular_velocity_covariance.data(), 9);
  m.linear_acceleration = ReadVector3(r, "linear_acceleration");
  r.F64Array("linear_acceleration_covariance", m.linear_acceleration_covariance.data(), 9);
  return m;
}

Twist DecodeTwist(const uint8_t* data, size_t size, Serialization serialization) {
  CdrReader r = Reader(data, size, serialization);
  return ReadTwist(r);
}

TFMessage DecodeTFMessage(const uint8_t* data, size_t size, Serialization serialization) {
  CdrReader r = Reader(data, size, serialization);
  TFMessage m;
  // A transform takes at least 4 + 8 (stamp, an empty frame) + 4 (child) + 56 bytes.
  const uint32_t n = r.Count("transforms", 72);
  m.transforms.resize(n);
  for (TransformStamped& t : m.transforms) {
    t.header = ReadHeader(r);
    t.child_frame_id = r.String("transforms.child_frame_id");
    t.transform.translation = ReadVector3(r, "transforms.transform.translation");
    t.transform.rotation = ReadQuaternion(r, "transforms.transform.rotation");
  }
  return m;
}

PoseStamped DecodePoseStamped(const uint8_t* data, size_t size, Serialization serialization) {
  CdrReader r = Reader(data, size, serialization);
  PoseStamped m;
  m.header = ReadHeader(r);
  m.pose.position = ReadVector3(r, "pose.position");
  m.pose.orientation = ReadQuaternion(r, "pose.orientation");
  return m;
}

PoseWithCovarianceStamped DecodePoseWithCovarianceStamped(const uint8_t* data, size_t size,
                                                          Serialization serialization) {
  CdrReader r = Reader(data, size, serialization);
  PoseWithCovarianceStamped m;
  m.header = ReadHeader(r);
  m.pose.position = ReadVector3(r, "pose.pose.position");
  m.pose.orientation = ReadQuaternion(r, "pose.pose.orientation");
  r.F64Array("pose.covariance", m.covariance.data(), 36);
  return m;
}

OccupancyGrid DecodeOccupancyGrid(const uint8_t* data, size_t size, Serialization serialization) {
  CdrReader r = Reader(data, size, serialization);
  OccupancyGrid m;
  m.header = ReadHeader(r);
  m.info.map_load_time.sec = r.I32("info.map_load_time.sec");
  m.info.map_load_time.nanosec = r.U32("info.map_load_time.nanosec");
  m.info.resolution = r.F32("info.resolution");
  m.info.width = r.U32("info.width");
  m.info.height = r.U32("info.height");
  m.info.origin.position = ReadVector3(r, "info.origin.position");
  m.info.origin.orientation = ReadQuaternion(r, "info.origin.orientation");
  m.data = r.I8s("data");
  if (uint64_t(m.info.width) * m.info.height != m.data.size()) {
    throw CdrError("data: " + std::to_string(m.data.size()) + " cells for a " + std::to_string(m.info.width) + " x " +
                       std::to_string(m.info.height) + " map",
                   r.offset());
  }
  return m;
}

String DecodeString(const uint8_t* data, size_t size, Serialization serialization) {
  CdrReader r = Reader(data, size, serialization);
  return String{r.String("data")};
}

Encoders DecodeEncoders(const uint8_t* data, size_t size, Serialization serialization) {
  CdrReader r = Reader(data, size, serialization);
  Encoders m;
  m.stamp.sec = r.I32("stamp.sec");
  m.stamp.nanosec = r.U32("stamp.nanosec");
  for (int64_t& t : m.ticks) t = r.I64("ticks");
  for (int32_t& d : m.delta_ticks) d = r.I32("delta_ticks");
  m.delta_time = r.I32("delta_time");
  return m;
}

MotorVelocity DecodeMotorVelocity(const uint8_t* data, size_t size, Serialization serialization) {
  CdrReader r = Reader(data, size, serialization);
  MotorVelocity m;
  for (float& v : m.velocity) v = r.F32("velocity");
  return m;
}

AprilTagDetectionArray DecodeAprilTagDetectionArray(const uint8_t* data, size_t size, Serialization serialization) {
  CdrReader r = Reader(data, size, serialization);
  AprilTagDetectionArray m;
  m.header = ReadHeader(r);
  // Each detection: a string (its length, and CDR's NUL), four int32/float32 and 19 float64.
  m.detections.resize(r.Count("detections", (r.ros1() ? 4 : 5) + 16 + 19 * 8));
  for (AprilTagDetection& d : m.detections) {
    d.family = r.String("detections.family");
    d.id = r.I32("detections.id");
    d.hamming = r.I32("detections.hamming");
    d.goodness = r.F32("detections.goodness");
    d.decision_margin = r.F32("detections.decision_margin");
    r.F64Array("detections.centre", d.centre.data(), d.centre.size());
    r.F64Array("detections.corners", d.corners.data(), d.corners.size());
    r.F64Array("detections.homography", d.homography.data(), d.homography.size());
  }
  return m;
}

std::vector<uint8_t> Encode(const LaserScan& m) {
  CdrWriter w;
  WriteHeader(w, m.header);
  for (float v :
       {m.angle_min, m.angle_max, m.angle_increment, m.time_increment, m.scan_time, m.range_min, m.range_max}) {
    w.F32(v);
  }
  w.F32s(m.ranges);
  w.F32s(m.intensities);
  return w.bytes();
}

std::vector<uint8_t> Encode(const Odometry& m) {
  CdrWriter w;
  WriteHeader(w, m.header);
  w.String(m.child_frame_id);
  WriteVector3(w, m.pose.position);
  WriteQuaternion(w, m.pose.orientation);
  w.F64Array(m.pose_covariance.data(), 36);
  WriteTwist(w, m.twist);
  w.F64Array(m.twist_covariance.data(), 36);
  return w.bytes();
}

std::vector<uint8_t> Encode(const Imu& m) {
  CdrWriter w;
  WriteHeader(w, m.header);
  WriteQuaternion(w, m.orientation);
  w.F64Array(m.orientation_covariance.data(), 9);
  WriteVector3(w, m.angular_velocity);
  w.F64Array(m.angular_velocity_covariance.data(), 9);
  WriteVector3(w, m.linear_acceleration);
  w.F64Array(m.linear_acceleration_covariance.data(), 9);
  return w.bytes();
}

std::vector<uint8_t> Encode(const Twist& m) {
  CdrWriter w;
  WriteTwist(w, m);
  return w.bytes();
}

std::vector<uint8_t> Encode(const TFMessage& m) {
  CdrWriter w;
  w.U32(static_cast<uint32_t>(m.transforms.size()));
  for (const TransformStamped& t : m.transforms) {
    WriteHeader(w, t.header);
    w.String(t.child_frame_id);
    WriteVector3(w, t.transform.translation);
    WriteQuaternion(w, t.transform.rotation);
  }
  return w.bytes();
}

std::vector<uint8_t> Encode(const PoseStamped& m) {
  CdrWriter w;
  WriteHeader(w, m.header);
  WriteVector3(w, m.pose.position);
  WriteQuaternion(w, m.pose.orientation);
  return w.bytes();
}

std::vector<uint8_t> Encode(const PoseWithCovarianceStamped& m) {
  CdrWriter w;
  WriteHeader(w, m.header);
  WriteVector3(w, m.pose.position);
  WriteQuaternion(w, m.pose.orientation);
  w.F64Array(m.covariance.data(), 36);
  return w.bytes();
}

std::vector<uint8_t> Encode(const PoseArray& m) {
  CdrWriter w;
  WriteHeader(w, m.header);
  w.U32(static_cast<uint32_t>(m.poses.size()));
  for (const Pose& p : m.poses) WriteVector3(w, p.position), WriteQuaternion(w, p.orientation);
  return w.bytes();
}

std::vector<uint8_t> Encode(const Path& m) {
  CdrWriter w;
  WriteHeader(w, m.header);
  w.U32(static_cast<uint32_t>(m.poses.size()));
  for (const PoseStamped& p : m.poses) {
    WriteHeader(w, p.header);
    WriteVector3(w, p.pose.position);
    WriteQuaternion(w, p.pose.orientation);
  }
  return w.bytes();
}

std::vector<uint8_t> Encode(const OccupancyGrid& m) {
  CdrWriter w;
  WriteHeader(w, m.header);
  w.I32(m.info.map_load_time.sec);
  w.U32(m.info.map_load_time.nanosec);
  w.F32(m.info.resolution);
  w.U32(m.info.width);
  w.U32(m.info.height);
  WriteVector3(w, m.info.origin.position);
  WriteQuaternion(w, m.info.origin.orientation);
  w.I8s(m.data);
  return w.bytes();
}

std::vector<uint8_t> Encode(const String& m) {
  CdrWriter w;
  w.String(m.data);
  return w.bytes();
}

std::vector<uint8_t> Encode(const Encoders& m) {
  CdrWriter w;
  w.I32(m.stamp.sec);
  w.U32(m.stamp.nanosec);
  for (int64_t t : m.ticks) w.I64(t);
  for (int32_t d : m.delta_ticks) w.I32(d);
  w.I32(m.delta_time);
  return w.bytes();
}

std::vector<uint8_t> Encode(const MotorVelocity& m) {
  CdrWriter w;
  for (float v : m.velocity) w.F32(v);
  return w.bytes();
}

std::vector<uint8_t> Encode(const MarkerArray& m) {
  CdrWriter w;
  w.U32(static_cast<uint32_t>(m.markers.size()));
  for (const Marker& k : m.markers) {
    WriteHeader(w, k.header);
    w.String(k.ns);
    w.I32(k.id), w.I32(k.type), w.I32(k.action);
    WriteVector3(w, k.pose.position);
    WriteQuaternion(w, k.pose.orientation);
    WriteVector3(w, k.scale);
    w.F32(k.color.r), w.F32(k.color.g), w.F32(k.color.b), w.F32(k.color.a);
    w.I32(k.lifetime.sec), w.U32(k.lifetime.nanosec);
    w.Bool(k.frame_locked);
    w.U32(static_cast<uint32_t>(k.points.size()));
    for (const Vector3& p : k.points) WriteVector3(w, p);
    w.U32(static_cast<uint32_t>(k.colors.size()));
    for (const ColorRGBA& c : k.colors) w.F32(c.r), w.F32(c.g), w.F32(c.b), w.F32(c.a);
    w.String("");              // texture_resource
    WriteHeader(w, Header{});  // texture (sensor_msgs/CompressedImage): header,
    w.String("");              // format,
    w.U32(0);                  // data
    w.U32(0);                  // uv_coordinates
    w.String(k.text);
    w.String("");            // mesh_resource
    w.String(""), w.U32(0);  // mesh_file: filename, data
    w.Bool(k.mesh_use_embedded_materials);
  }
  return w.bytes();
}

std::vector<uint8_t> Encode(const AprilTagDetectionArray& m) {
  CdrWriter w;
  WriteHeader(w, m.header);
  w.U32(static_cast<uint32_t>(m.detections.size()));
  for (const AprilTagDetection& d : m.detections) {
    w.String(d.family);
    w.I32(d.id), w.I32(d.hamming);
    w.F32(d.goodness), w.F32(d.decision_margin);
    w.F64Array(d.centre.data(), d.centre.size());
    w.F64Array(d.corners.data(), d.corners.size());
    w.F64Array(d.homography.data(), d.homography.size());
  }
  return w.bytes();
}

double Yaw(const Quaternion& q) {
  return std::atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z));
}
Quaternion FromYaw(double yaw) { return {0.0, 0.0, std::sin(yaw / 2), std::cos(yaw / 2)}; }

std::vector<uint8_t> EncodeTriggerRequest(const ServiceHeader* header) {
  CdrWriter w;
  if (header) w.U64(header->guid), w.I64(header->sequence);
  w.U8(0);  // structure_needs_at_least_one_member
  return w.bytes();
}

bool DecodeTriggerRequest(const uint8_t* data, size_t size, ServiceHeader* header) {
  CdrReader r(data, size);
  // The placeholder alone (padded to 4 bytes on the wire), or the 16-byte header and it.
  const bool with_header = r.remaining() >= 17;
  if (with_header) {
    const uint64_t guid = r.U64("request_header.guid");
    const int64_t sequence = r.I64("request_header.sequence");
    if (header) *header = {guid, sequence};
  }
  r.U8("structure_needs_at_least_one_member");
  return with_header;
}

std::vector<uint8_t> Encode(const TriggerResponse& m, const ServiceHeader* header) {
  CdrWriter w;
  if (header) w.U64(header->guid), w.I64(header->sequence);
  w.Bool(m.success);
  w.String(m.message);
  return w.bytes();
}

TriggerResponse DecodeTriggerResponse(const uint8_t* data, size_t size) {
  CdrReader r(data, size);
  TriggerResponse m;
  m.success = r.Bool("success");
  m.message = r.String("message");
  return m;
}

}  // namespace mbot::ros2
