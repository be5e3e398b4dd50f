// The ROS 2 transport's source and output types and their keys:
//   source mcap     a ROS 2 bag: rosbag2 with storage mcap (the bag's folder, or one .mcap file), or
//                   any MCAP file of ROS 2 messages (cdr), picked by the file's magic bytes;
//   output rosbag2  records the run as a ROS 2 bag (run.mcap + metadata.yaml in the output folder);
//                   [record] format = mcap on any config is this output;
// ROS names are the pipeline's topics through a TopicTable (`topics`, with the MBot's names as
// defaults: LIDAR:/scan, MBOT_ODOMETRY:/odom …); messages become events by their type.
#pragma once

#include <cstdint>
#include <string>

#include "mbot/msgs/topics.hpp"

namespace mbot::ros2 {

// The MBot's ROS 2 names for the pipeline's topics (what mbot_ros2_ws and its lab nodes publish).
msgs::TopicTable DefaultTopics();

// The QoS of a ROS 2 topic (rosbag2's offered_qos_profiles, the DDS readers' and writers').
struct Qos {
  int depth = 10;
  bool reliable = true;
  bool transient_local = false;
};
// What the MBot offers on a topic: sensors from the firmware best effort, the lidar and the
// autonomy's topics reliable, /map and /tf_static reliable + transient local (a late RViz gets them).
Qos DefaultQos(const std::string& topic);

// [source] type = mcap.
struct BagSourceOptions {
  msgs::TopicTable topics = DefaultTopics();
  // The robot's frame: the lidar's mount is the transform from it to the scan's frame, from
  // /tf_static. "" = the frame /odom's messages move (child_frame_id), else base_footprint.
  std::string robot_frame;
  // Messages are re-sorted by log time within this window (rosbag2 writes them as they arrive).
  int64_t reorder_window_us = 100000;
};

// Registers the ROS 2 source (and output) types (idempotent).
void RegisterRos2Transport();

}  // namespace mbot::ros2
