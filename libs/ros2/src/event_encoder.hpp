// The pipeline's events as the MBot generation's ROS 2 messages, for every ROS 2 output (the
// rosbag2 recorder, the DDS transport): a scan is a LaserScan (and /tf_static when the lidar's
// mount changed), odometry an Odometry and odom → base_footprint on /tf, the SLAM pose a
// PoseStamped and map → odom on /tf, the map an OccupancyGrid (0/100/-1), particles a PoseArray,
// the path a nav_msgs/Path, frontiers a MarkerArray (one POINTS marker per region), the mission's
// state a std_msgs/String ("exploring" or "completed: detail"), encoders mbot_interfaces/Encoders.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mbot/common/config.hpp"
#include "mbot/msgs/visitor.hpp"
#include "mbot/ros2/messages.hpp"
#include "mbot/ros2/ros2_transport.hpp"

namespace mbot::ros2 {

struct Frames {
  std::string map = "map", odom = "odom", robot = "base_footprint";
  std::string lidar = "lidar_link", imu = "base_link";
  std::string camera = "camera";  // the image's frame (camera_ros's default): tag detections and their /tf
  // The MBot's robot_state_publisher tree: robot → base_link (z base_link_z_m), base_link → lidar
  // (the lidar's planar mount, z lidar_z_m above base_link). base_link "" (or the robot's frame):
  // the mount straight from the robot's frame.
  std::string base_link = "base_link";
  double base_link_z_m = 0.042, lidar_z_m = 0.142;
};

struct EncodedMessage {
  std::string topic;  // the ROS name ("/scan")
  const char* type;   // "sensor_msgs/msg/LaserScan"
  int64_t t_us;
  std::vector<uint8_t> cdr;
};

class EventEncoder : private msgs::EventVisitor {
 public:
  EventEncoder(msgs::TopicTable topics, Frames frames) : topics_(std::move(topics)), frames_(std::move(frames)) {}
  // Appends the messages `event` becomes; false when it has no ROS 2 message.
  bool Encode(const msgs::Event& event, std::vector<EncodedMessage>* out);
  // The ROS name an event goes out under (poses by their kind; a channel with no ROS name by its kind).
  std::string TopicFor(const msgs::Event& event) const;
  long long binned() const { return binned_; }  // scans binned onto uniform angles
  const Frames& frames() const { return frames_; }

 private:
  bool Lidar(const msgs::Event&, const msgs::LidarScan&) override;
  bool Pose(const msgs::Event&, const msgs::Pose2D&) override;
  bool Encoders(const msgs::Event&, const msgs::EncoderTicks&) override;
  bool Wheels(const msgs::Event&, const msgs::WheelSpeeds&) override;
  bool ImuReading(const msgs::Event&, const msgs::Imu&) override;
  bool Motors(const msgs::Event&, const msgs::MotorCommand&) override;
  bool Map(const msgs::Event&, const msgs::OccupancyGrid&) override;
  bool PathPoses(const msgs::Event&, const msgs::Path&) override;
  bool ParticleSet(const msgs::Event&, const msgs::Particles&) override;
  bool FrontierSet(const msgs::Event&, const msgs::Frontiers&) override;
  bool Mission(const msgs::Event&, const msgs::MissionStatus&) override;
  bool Tags(const msgs::Event&, const msgs::TagSightings&) override;
  void Put(std::string topic, const char* type, int64_t t_us, std::vector<uint8_t> cdr);

  msgs::TopicTable topics_;
  Frames frames_;
  std::vector<EncodedMessage>* out_ = nullptr;
  msgs::Pose2D mount_, odom_;
  bool mount_written_ = false, have_odom_ = false;
  long long binned_ = 0;
};

// The keys of the robot's /tf_static tree: base_link_frame, base_link_z_m, lidar_z_m (`what`
// starts their documentation: "ros2", "rosbag2").
void ParseTreeFrames(config::Section& s, const std::string& what, Frames* frames);

// "completed: detail" → the state and detail (nullopt when the state is not one of ours).
std::optional<msgs::MissionStatus> ParseMissionState(const std::string& text);

}  // namespace mbot::ros2
