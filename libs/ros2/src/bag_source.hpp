// Replays a ROS 2 bag (rosbag2, storage mcap) or an MCAP file of ROS 2 messages as an Event stream:
// LaserScan → lidar (the mount from /tf_static), Odometry → odometry, Imu → imu, Twist →
// velocity command, PoseStamped / PoseWithCovarianceStamped → the pose role of their topic.
#pragma once

#include <climits>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "mbot/msgs/source.hpp"
#include "mbot/ros2/mcap_reader.hpp"
#include "mbot/ros2/ros1_bag.hpp"
#include "mbot/ros2/messages.hpp"
#include "mbot/ros2/ros2_transport.hpp"
#include "mbot/ros2/transforms.hpp"
#include "message_decoder.hpp"

namespace mbot::ros2 {

// One file of a bag, MCAP or ROS 1: its messages in file order and what its channels carry.
class BagFile {
 public:
  struct ChannelDesc {
    std::string topic, type, encoding;  // type as ROS 2 names it ("sensor_msgs/msg/LaserScan"); cdr or ros1
  };
  virtual ~BagFile() = default;
  // Throws std::runtime_error (McapError, Ros1BagError) naming the file and offset of what is bad.
  virtual bool Next(McapMessage* message) = 0;
  virtual std::optional<ChannelDesc> Channel(uint16_t id) const = 0;
  virtual uint64_t position() const = 0;
  virtual long long messages() const = 0;
  virtual long long chunks() const = 0;
  virtual long long crcs() const = 0;
  virtual bool truncated() const = 0;
};
// Opens `path` by its magic bytes: MCAP or a ROS 1 bag.
std::unique_ptr<BagFile> OpenBagFile(const std::string& path);

// The files of a bag: a folder's .mcap files in metadata.yaml's order (else by name), or the file.
std::vector<std::string> BagFiles(const std::string& path);

class McapBagSource : public msgs::Source {
 public:
  explicit McapBagSource(const msgs::SourceOptions& options);
  std::optional<msgs::Event> Next() override;
  double Progress() const override;
  std::string Format() const override { return ros1_ ? "ROS 1 bag" : "ROS 2 bag (MCAP)"; }
  std::vector<std::pair<std::string, std::string>> Details() const override;

 private:
  // What a channel's messages become, worked out once per channel.
  struct Route {
    MessageDecoder::Type type = MessageDecoder::Type::kUnknown;
    std::string wire, topic, type_name;
    Serialization serialization = Serialization::kCdr;
    msgs::ChannelInfo* info = nullptr;  // nullptr: a channel the file never declared
  };
  Route RouteOf(uint16_t channel_id);
  bool ReadMore();  // one more message into pending_; false at the end of the last file
  void Handle(const McapMessage& m);
  void Reject(const std::string& topic, const McapMessage& m, const std::string& why);

  msgs::SourceOptions options_;
  BagSourceOptions bag_;
  std::vector<std::string> files_;
  size_t file_index_ = 0;
  std::unique_ptr<BagFile> reader_;
  bool ros1_ = false;
  std::map<uint16_t, Route> routes_;             // of the current file
  uint64_t bytes_before_ = 0, bytes_total_ = 0;  // of the files before the current one, of all
  std::multimap<int64_t, msgs::Event> pending_;  // by t_us, within the reorder window
  int64_t last_emitted_us_ = INT64_MIN;
  bool eof_ = false;
  MessageDecoder decoder_;
  std::set<std::string> warned_;
  long long messages_ = 0, chunks_ = 0, crcs_ = 0;
};

}  // namespace mbot::ros2
