// output rosbag2: the run's events as a ROS 2 bag — one MCAP file (profile ros2, ros2msg schemas,
// cdr, each channel's offered_qos_profiles, the rosbag2 metadata record) and metadata.yaml beside
// it, in the output folder, as `ros2 bag record -s mcap` writes them; Foxglove, rosbags and
// `ros2 bag info` open it. Frames are the MBot's (map → odom → base_footprint → lidar_link).
#pragma once

#include <map>
#include <memory>
#include <string>

#include "mbot/msgs/stage.hpp"
#include "mbot/msgs/visitor.hpp"
#include "mbot/ros2/mcap_writer.hpp"
#include "mbot/ros2/messages.hpp"
#include "mbot/ros2/ros2_transport.hpp"

namespace mbot::config {
class Section;
}

namespace mbot::ros2 {

struct BagQos {
  int depth = 10;
  bool reliable = true;
  bool transient_local = false;
};
// The QoS the MBot offers on a topic (what the bag's metadata says each was recorded with).
BagQos DefaultQos(const std::string& topic);

struct BagRecorderOptions {
  std::string file = "run.mcap";
  std::string compression = "zstd";
  msgs::TopicTable topics = DefaultTopics();
  std::string map_frame = "map", odom_frame = "odom", robot_frame = "base_footprint";
  std::string lidar_frame = "lidar_link", imu_frame = "base_link";
};
BagRecorderOptions ParseBagRecorderOptions(config::Section& section);

class BagRecorder : public msgs::Output, private msgs::EventVisitor {
 public:
  explicit BagRecorder(BagRecorderOptions options);
  ~BagRecorder() override;
  void Open(const msgs::RunContext& context) override;
  void Send(const msgs::Event& event) override;
  void Close(bool interrupted) override;

 private:
  bool Lidar(const msgs::Event&, const msgs::LidarScan&) override;
  bool Pose(const msgs::Event&, const msgs::Pose2D&) override;
  bool ImuReading(const msgs::Event&, const msgs::Imu&) override;
  bool Motors(const msgs::Event&, const msgs::MotorCommand&) override;
  bool Map(const msgs::Event&, const msgs::OccupancyGrid&) override;
  bool PathPoses(const msgs::Event&, const msgs::Path&) override;
  bool ParticleSet(const msgs::Event&, const msgs::Particles&) override;

  std::string TopicFor(const msgs::Event& event) const;
  uint16_t Channel(const std::string& topic, const std::string& type);  // 0: the topic has another type
  void Put(const std::string& topic, const std::string& type, int64_t t_us, const std::vector<uint8_t>& cdr);
  std::string MetadataYaml(bool for_file) const;

  BagRecorderOptions o_;
  std::string dir_;
  std::unique_ptr<McapWriter> writer_;
  std::map<std::string, uint16_t> schemas_;
  struct ChannelInfo {
    uint16_t id = 0;
    std::string type;
    BagQos qos;
  };
  std::map<std::string, ChannelInfo> channels_;
  std::map<std::string, long long> skipped_;
  msgs::Pose2D mount_, odom_;
  bool mount_written_ = false, have_odom_ = false;
  long long binned_ = 0;
};

}  // namespace mbot::ros2
