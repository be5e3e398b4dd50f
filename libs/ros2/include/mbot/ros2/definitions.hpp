// The ROS 2 message definitions (.msg text, written from common_interfaces, geometry2 and
// rcl_interfaces' builtin_interfaces) of the types the recorder writes, in the form rosbag2 stores
// them as an MCAP `ros2msg` schema: the type's own text, then each type it uses once, after a line
// of 80 '=' and "MSG: pkg/Type".
#pragma once

#include <string>
#include <vector>

namespace mbot::ros2 {

// "sensor_msgs/msg/LaserScan" → its concatenated definition; throws std::out_of_range when the type
// is not one of ours.
std::string Definition(const std::string& type);
// Every type Definition knows.
std::vector<std::string> DefinedTypes();

}  // namespace mbot::ros2
