// ROS 2 live, over DDS (dds.hpp): Ros2Node subscribes to ROS topics and turns their messages into
// validated events (message_decoder.hpp: the lidar's mount from /tf_static, a malformed message
// counted and named, never passed on), and publishes events as ROS 2 messages (event_encoder.hpp)
// on writers with each topic's QoS. The live source (`[source] type = ros2_live`) is a
// msgs::LiveSource on it; the simulated robot's side is the `ros2_bridge` stage.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "event_encoder.hpp"
#include "message_decoder.hpp"
#include "mbot/msgs/live_source.hpp"
#include "mbot/msgs/stage.hpp"
#include "mbot/ros2/dds.hpp"
#include "mbot/ros2/messages.hpp"

namespace mbot::config {
class Section;
}

namespace mbot::ros2 {

struct Ros2NodeOptions {
  DdsOptions dds;
  msgs::TopicTable topics = DefaultTopics();
  Frames frames;
  // Scans without a mount are dropped this long (then: centre). A latched /tf_static reaches a reader
  // only after discovery and the writer's resend: from a Fast DDS robot on a loaded machine that took
  // more than 3 s, and the scans mapped meanwhile with the lidar at the centre stayed in the map.
  int64_t wait_for_mount_us = 10000000;
  std::string robot_frame;  // whose transform to the scan's frame is the lidar's mount ("" = /odom's child)
  // ROS types of the topics read (pipeline topic → type); the MBot's by default (DefaultRosType).
  std::map<std::string, std::string> types;
};
// The ROS 2 type a pipeline topic carries on the MBot ("" when none is known).
std::string DefaultRosType(const std::string& topic);

// [source] / [stage] keys shared by ros2_live and ros2_bridge: url (dds:<domain>), topics, frames.
// `receives_scans`: the node may subscribe to scans (robot_frame, wait_for_mount_s are its keys).
Ros2NodeOptions ParseRos2NodeOptions(config::Section& section, const std::string& url, const std::string& node,
                                     bool receives_scans);

class Ros2Node {
 public:
  // Subscribes to `channels` (pipeline topics; /tf_static always, for the mount). Throws
  // std::runtime_error naming a channel with no known ROS type or a topic DDS refuses.
  Ros2Node(Ros2NodeOptions options, const std::vector<std::string>& channels, const msgs::ChannelRoles& roles);

  // Waits up to timeout_ms, then takes what arrived: events in arrival order, t_us = when DDS received them.
  void Poll(int timeout_ms, std::vector<msgs::Event>* out);
  // Publishes the messages the event becomes (a writer per topic, made on first use with the
  // topic's QoS); false when it has none.
  bool Publish(const msgs::Event& event);
  // A writer for `topic` now (so discovery is under way before the first message).
  void PrepareWriter(const std::string& wire, const std::string& type);

  // A std_srvs/Trigger service (`service`, e.g. "/reset_odometry") this node answers: every request
  // Poll takes is answered with `handler`'s response, in the request's form (with rmw_cyclonedds's
  // header when it came with one, as a client on rmw_cyclonedds_cpp sends it).
  void ServeTrigger(const std::string& service, std::function<TriggerResponse()> handler);
  // Calls a std_srvs/Trigger service once, as the MBot's micro-ROS agent answers it (the request
  // alone; the agent puts the request's identity in the RTPS message, which Cyclone's API does not
  // show, so the first reply after the request is taken): waits up to timeout_ms for the service to
  // be matched and to answer; the node's topics keep what arrives meanwhile for the next Poll.
  // nullopt when no reply came in time.
  std::optional<TriggerResponse> CallTrigger(const std::string& service, int timeout_ms);

  struct TopicStats {
    std::string type;
    long long received = 0, rejected = 0, published = 0;
    std::string last_error;
  };
  const std::map<std::string, TopicStats>& stats() const { return stats_; }  // by ROS name
  long long rejected_total() const;
  DdsParticipant& dds() { return dds_; }
  std::string where() const { return "DDS domain " + std::to_string(dds_.domain_id()); }
  std::vector<std::pair<std::string, std::string>> Details() const;

 private:
  struct Route {
    std::string topic, wire, type;
    MessageDecoder::Type kind;
  };
  Ros2NodeOptions o_;
  msgs::ChannelRoles roles_;
  DdsParticipant dds_;
  MessageDecoder decoder_;
  EventEncoder encoder_;
  std::vector<Route> routes_;           // by reader index
  std::map<std::string, int> writers_;  // by ROS name
  std::map<std::string, std::string> writer_types_;
  std::map<std::string, TopicStats> stats_;
  std::vector<EncodedMessage> encoded_;
  struct TriggerServer {
    std::string service;
    int reply_writer = -1;
    std::function<TriggerResponse()> handler;
  };
  std::map<int, TriggerServer> servers_;  // by request reader index
  std::set<int> service_readers_;         // reply readers of calls: not topics
};

std::unique_ptr<msgs::Source> OpenRos2Live(const msgs::SourceOptions& options);
msgs::StageType Ros2BridgeStageType();
// output ros2: the run's events published over DDS as the MBot's messages (a replay or a simulation
// seen in RViz or Foxglove over ROS 2, or driving other ROS 2 nodes).
msgs::OutputType Ros2OutputType();

// [source] type = ros2_live: the node's options and the live keys.
struct Ros2LiveOptions {
  Ros2NodeOptions node;
  msgs::LiveSourceOptions live;
  // A std_srvs/Trigger service called once at start to zero the robot's odometry (the MBot's
  // /reset_odometry); "" = none.
  std::string reset_odometry_service;
};

}  // namespace mbot::ros2
