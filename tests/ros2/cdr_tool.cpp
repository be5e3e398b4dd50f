// The CDR codec from the command line, for tests/ros2/rosbags_interop.py (rosbags, an independent
// implementation, writes and reads the other side):
//   mbot_cdr_tool decode <type> <cdr file>          the message as JSON on stdout
//   mbot_cdr_tool encode <type> <json file> <out>   the JSON message as CDR
// <type>: sensor_msgs/msg/LaserScan, nav_msgs/msg/Odometry, sensor_msgs/msg/Imu,
// geometry_msgs/msg/Twist, tf2_msgs/msg/TFMessage. Exit 1 with the reader's error on bad input.
#include <fstream>
#include <iostream>
#include <iterator>

#include <nlohmann/json.hpp>

#include "mbot/ros2/messages.hpp"

using nlohmann::json;
using namespace mbot::ros2;

namespace {

json J(const Time& t) { return {{"sec", t.sec}, {"nanosec", t.nanosec}}; }
json J(const Header& h) { return {{"stamp", J(h.stamp)}, {"frame_id", h.frame_id}}; }
json J(const Vector3& v) { return {{"x", v.x}, {"y", v.y}, {"z", v.z}}; }
json J(const Quaternion& q) { return {{"x", q.x}, {"y", q.y}, {"z", q.z}, {"w", q.w}}; }
json J(const Twist& t) { return {{"linear", J(t.linear)}, {"angular", J(t.angular)}}; }
template <size_t N>
json J(const std::array<double, N>& a) {
  return std::vector<double>(a.begin(), a.end());
}

Header H(const json& j) { return {{j["stamp"]["sec"], j["stamp"]["nanosec"]}, j["frame_id"]}; }
Vector3 V(const json& j) { return {j["x"], j["y"], j["z"]}; }
Quaternion Q(const json& j) { return {j["x"], j["y"], j["z"], j["w"]}; }
Twist T(const json& j) { return {V(j["linear"]), V(j["angular"])}; }
template <size_t N>
void A(const json& j, std::array<double, N>* a) {
  for (size_t i = 0; i < N; ++i) (*a)[i] = j.at(i);
}

json Decode(const std::string& type, const std::vector<uint8_t>& b) {
  if (type == kLaserScanType) {
    const LaserScan m = DecodeLaserScan(b.data(), b.size());
    return {{"header", J(m.header)},
            {"angle_min", m.angle_min},
            {"angle_max", m.angle_max},
            {"angle_increment", m.angle_increment},
            {"time_increment", m.time_increment},
            {"scan_time", m.scan_time},
            {"range_min", m.range_min},
            {"range_max", m.range_max},
            {"ranges", m.ranges},
            {"intensities", m.intensities}};
  }
  if (type == kOdometryType) {
    const Odometry m = DecodeOdometry(b.data(), b.size());
    return {{"header", J(m.header)},
            {"child_frame_id", m.child_frame_id},
            {"pose",
             {{"pose", {{"position", J(m.pose.position)}, {"orientation", J(m.pose.orientation)}}},
              {"covariance", J(m.pose_covariance)}}},
            {"twist", {{"twist", J(m.twist)}, {"covariance", J(m.twist_covariance)}}}};
  }
  if (type == kImuType) {
    const Imu m = DecodeImu(b.data(), b.size());
    return {{"header", J(m.header)},
            {"orientation", J(m.orientation)},
            {"orientation_covariance", J(m.orientation_covariance)},
            {"angular_velocity", J(m.angular_velocity)},
            {"angular_velocity_covariance", J(m.angular_velocity_covariance)},
            {"linear_acceleration", J(m.linear_acceleration)},
            {"linear_acceleration_covariance", J(m.linear_acceleration_covariance)}};
  }
  if (type == kTwistType) return J(DecodeTwist(b.data(), b.size()));
  if (type == kTFMessageType) {
    json out = {{"transforms", json::array()}};
    for (const TransformStamped& t : DecodeTFMessage(b.data(), b.size()).transforms) {
      out["transforms"].push_back(
          {{"header", J(t.header)},
           {"child_frame_id", t.child_frame_id},
           {"transform", {{"translation", J(t.transform.translation)}, {"rotation", J(t.transform.rotation)}}}});
    }
    return out;
  }
  throw std::invalid_argument("unknown type " + type);
}

std::vector<uint8_t> Encode(const std::string& type, const json& j) {
  if (type == kLaserScanType) {
    LaserScan m;
    m.header = H(j["header"]);
    m.angle_min = j["angle_min"], m.angle_max = j["angle_max"], m.angle_increment = j["angle_increment"];
    m.time_increment = j["time_increment"], m.scan_time = j["scan_time"];
    m.range_min = j["range_min"], m.range_max = j["range_max"];
    m.ranges = j["ranges"].get<std::vector<float>>();
    m.intensities = j["intensities"].get<std::vector<float>>();
    return mbot::ros2::Encode(m);
  }
  if (type == kOdometryType) {
    Odometry m;
    m.header = H(j["header"]);
    m.child_frame_id = j["child_frame_id"];
    m.pose.position = V(j["pose"]["pose"]["position"]);
    m.pose.orientation = Q(j["pose"]["pose"]["orientation"]);
    A(j["pose"]["covariance"], &m.pose_covariance);
    m.twist = T(j["twist"]["twist"]);
    A(j["twist"]["covariance"], &m.twist_covariance);
    return mbot::ros2::Encode(m);
  }
  if (type == kImuType) {
    Imu m;
    m.header = H(j["header"]);
    m.orientation = Q(j["orientation"]);
    A(j["orientation_covariance"], &m.orientation_covariance);
    m.angular_velocity = V(j["angular_velocity"]);
    A(j["angular_velocity_covariance"], &m.angular_velocity_covariance);
    m.linear_acceleration = V(j["linear_acceleration"]);
    A(j["linear_acceleration_covariance"], &m.linear_acceleration_covariance);
    return mbot::ros2::Encode(m);
  }
  if (type == kTwistType) return mbot::ros2::Encode(T(j));
  if (type == kTFMessageType) {
    TFMessage m;
    for (const json& t : j["transforms"]) {
      m.transforms.push_back(
          {H(t["header"]), t["child_frame_id"], {V(t["transform"]["translation"]), Q(t["transform"]["rotation"])}});
    }
    return mbot::ros2::Encode(m);
  }
  throw std::invalid_argument("unknown type " + type);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "decode" && argc == 4) {
      std::ifstream in(argv[3], std::ios::binary);
      const std::vector<uint8_t> b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      std::cout << Decode(argv[2], b).dump() << "\n";
      return 0;
    }
    if (mode == "encode" && argc == 5) {
      std::ifstream in(argv[3]);
      const std::vector<uint8_t> b = Encode(argv[2], json::parse(in));
      std::ofstream(argv[4], std::ios::binary).write(reinterpret_cast<const char*>(b.data()), b.size());
      return 0;
    }
    std::cerr << "usage: mbot_cdr_tool decode <type> <cdr file> | encode <type> <json file> <out>\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "mbot_cdr_tool: " << e.what() << "\n";
    return 1;
  }
}
