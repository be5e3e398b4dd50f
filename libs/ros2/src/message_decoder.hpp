// The MBot generation's ROS 2 messages as the pipeline's events, for every ROS 2 input (bags, the
// DDS transport): LaserScan → lidar (the mount from /tf_static), Odometry → odometry, Imu → imu,
// Twist → velocity command, PoseStamped / PoseWithCovarianceStamped → the pose role of their
// topic, Encoders → encoder ticks, MotorVelocity → wheel speeds, OccupancyGrid → a map, String on the mission topic →
// the mission's state; /tf_static builds the static tree (loops and second parents refused).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "mbot/msgs/source.hpp"
#include "mbot/ros2/messages.hpp"
#include "mbot/ros2/transforms.hpp"

namespace mbot::ros2 {

class MessageDecoder {
 public:
  enum class Type {
    kUnknown,
    kScan,
    kOdometry,
    kImu,
    kTwist,
    kTfStatic,
    kTf,
    kPoseStamped,
    kPoseWithCovariance,
    kEncoders,
    kMotorVelocity,
    kMap,
    kString
  };
  // What a topic's messages are, by their ROS 2 type (and, for TFMessage, the topic).
  static Type TypeOf(const std::string& ros_type, const std::string& wire);

  // `robot_frame`: the lidar's mount is the transform from it to the scan's frame ("" = the frame
  // /odom moves, else base_footprint). `where` starts warnings (a file, "ros2").
  MessageDecoder(std::string robot_frame, std::string where) : robot_frame_(std::move(robot_frame)), where_(where) {}

  // Decodes one message on pipeline topic `topic` (ROS name `wire`) into `ev` (kind, stamp_us,
  // payload; the caller sets t_us and channel). False when it is no event (a /tf_static message,
  // which only feeds the tree; an empty scan; a mission string that names no state). Throws
  // std::runtime_error (CdrError naming field and offset) when the message is malformed;
  // `*refused` names /tf_static transforms that were refused (a loop, a second parent).
  bool Decode(Type type, const std::string& topic, const std::string& wire, const uint8_t* data, size_t size,
              Serialization serialization, int64_t t_us, const msgs::ChannelRoles& roles, msgs::Event* ev,
              std::string* refused);

  // Scans whose frame /tf_static does not connect yet are dropped for this long after the first
  // (live: the latched /tf_static arrives once discovery matched its writer); after it, and with 0
  // (bags), they are taken as mounted at the robot's centre, facing forward, with a warning.
  void WaitForMount(int64_t us) { wait_for_mount_us_ = us; }

  // The lidar mounts found so far, for a summary ("lidar lidar_link": "x 0.000 m, …").
  std::vector<std::pair<std::string, std::string>> Details() const;

 private:
  bool LidarEvent(const LaserScan& scan, const std::string& topic, msgs::Event* ev);
  std::optional<msgs::Pose2D> Mount(const std::string& frame, bool* mirrored);

  std::string robot_frame_, where_;
  StaticTransforms tf_static_;
  std::string odom_child_frame_;
  struct MountCache {
    msgs::Pose2D pose;
    bool mirrored = false;
  };
  std::map<std::string, MountCache> mounts_;  // scan frame → its mount, once the tree connects it
  std::set<std::string> warned_;
  int64_t wait_for_mount_us_ = 0, first_unmounted_us_ = 0;
  long long scans_waiting_for_mount_ = 0;
};

}  // namespace mbot::ros2
