// ROS 2 on the wire without a ROS installation: a DDS participant (Eclipse Cyclone DDS, the DDS of
// rmw_cyclonedds_cpp) whose readers and writers carry CDR payloads as they are — the messages are
// encoded and decoded by messages.hpp, written from the public .msg files, and Cyclone only moves
// the bytes (a serialized type of its own, as rmw_cyclonedds does). ROS 2's conventions: topic
// "/scan" is DDS topic "rt/scan", type sensor_msgs/msg/LaserScan is "sensor_msgs::msg::dds_::LaserScan_",
// keyless, XCDR1; QoS as the topic's (a best-effort reader matches both kinds of writer). A sample
// larger than max_sample_bytes is dropped on receipt and counted, never allocated.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "mbot/ros2/ros2_transport.hpp"

namespace mbot::ros2 {

// "/scan" → "rt/scan"; "sensor_msgs/msg/LaserScan" → "sensor_msgs::msg::dds_::LaserScan_".
std::string DdsTopicName(const std::string& ros_topic);
std::string DdsTypeName(const std::string& ros_type);

struct DdsOptions {
  int domain_id = 0;                    // ROS_DOMAIN_ID
  size_t max_sample_bytes = 64u << 20;  // larger samples are dropped (and counted) on receipt
  std::string config;                   // Cyclone XML fragments or a file URI ("" = CYCLONEDDS_URI)
  // The ROS 2 node this participant is (namespace "/"): announced on ros_discovery_info as
  // rmw_cyclonedds does, with the GIDs of its readers and writers, so `ros2 node list` and
  // `ros2 node info` name it. "" = no announcement.
  std::string node_name = "mbot_nav";
};

class DdsParticipant {
 public:
  // Throws std::runtime_error naming the domain when Cyclone cannot create the participant.
  explicit DdsParticipant(const DdsOptions& options);
  ~DdsParticipant();
  DdsParticipant(const DdsParticipant&) = delete;
  DdsParticipant& operator=(const DdsParticipant&) = delete;

  // A reader or writer on ROS topic `topic` of ROS type `type`; returns its index. Throws
  // std::runtime_error naming the topic when Cyclone refuses it (a name DDS cannot take).
  // `dds_name`: `topic` is the DDS topic as it is (a service's rq/…Request, rr/…Reply), not a ROS
  // topic put under rt/.
  int AddReader(const std::string& topic, const std::string& type, const Qos& qos, bool dds_name = false);
  int AddWriter(const std::string& topic, const std::string& type, const Qos& qos, bool dds_name = false);

  // Writes one CDR payload (with its 4-byte encapsulation header); false when it could not be.
  bool Write(int writer, const uint8_t* cdr, size_t size);

  struct Sample {
    int reader;
    const uint8_t* data;  // the CDR payload, with its encapsulation header
    size_t size;
    int64_t source_time_us;  // the writer's timestamp
    int64_t arrival_us;      // when Cyclone's receive thread got it (wall clock, µs since the epoch)
  };
  // Waits up to timeout_ms for data on any reader, then takes every sample waiting on all of them.
  void Take(int timeout_ms, const std::function<void(const Sample&)>& on_sample);
  // Sleeps timeout_ms, then takes what waits on `reader` alone (the others keep theirs).
  void TakeFrom(int reader, int timeout_ms, const std::function<void(const Sample&)>& on_sample);

  // Remote endpoints matched so far (discovery), for tests and start-up waits.
  int MatchedReaders(int writer) const;
  int MatchedWriters(int reader) const;
  long long too_large() const;  // samples dropped for exceeding max_sample_bytes
  int domain_id() const { return options_.domain_id; }
  const std::string& reader_topic(int reader) const;
  const std::string& writer_topic(int writer) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  DdsOptions options_;
};

}  // namespace mbot::ros2
