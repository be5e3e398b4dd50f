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
#include "event_encoder.hpp"
#include "mbot/ros2/ros2_transport.hpp"

namespace mbot::config {
class Section;
}

namespace mbot::ros2 {

using BagQos = Qos;  // what the bag's metadata says each topic was recorded with (DefaultQos)

struct BagRecorderOptions {
  std::string file = "run.mcap";
  std::string compression = "zstd";
  msgs::TopicTable topics = DefaultTopics();
  std::string map_frame = "map", odom_frame = "odom", robot_frame = "base_footprint";
  std::string lidar_frame = "lidar_link", imu_frame = "base_link", camera_frame = "camera";
  Frames tree;  // base_link and the heights of the /tf_static tree (the other frames above)
};
BagRecorderOptions ParseBagRecorderOptions(config::Section& section);

class BagRecorder : public msgs::Output {
 public:
  explicit BagRecorder(BagRecorderOptions options);
  ~BagRecorder() override;
  void Open(const msgs::RunContext& context) override;
  void Send(const msgs::Event& event) override;
  void Close(bool interrupted) override;

 private:
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
  EventEncoder encoder_;
  std::vector<EncodedMessage> encoded_;
};

}  // namespace mbot::ros2
