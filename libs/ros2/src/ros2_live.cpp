#include "ros2_live.hpp"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <stdexcept>
#include <thread>

#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/msgs/loop_latency.hpp"
#include "mbot/msgs/topics.hpp"

namespace mbot::ros2 {

using msgs::Event;
using msgs::EventKind;
namespace topics = msgs::topics;

std::string DefaultRosType(const std::string& topic) {
  static const std::map<std::string, std::string> types = {{topics::kLidar, kLaserScanType},
                                                           {topics::kOdometry, kOdometryType},
                                                           {topics::kImu, kImuType},
                                                           {topics::kEncoders, kEncodersType},
                                                           {topics::kMotorVelocity, kMotorVelocityType},
                                                           {topics::kVelocityCommand, kTwistType},
                                                           {topics::kSlamMap, kOccupancyGridType},
                                                           {topics::kSlamPose, kPoseStampedType},
                                                           {topics::kTruePose, kPoseStampedType},
                                                           {topics::kMissionStatus, kStringType},
                                                           {topics::kSlamParticles, kPoseArrayType},
                                                           {topics::kPath, kPathType},
                                                           {topics::kFrontiers, kMarkerArrayType}};
  auto it = types.find(topic);
  return it == types.end() ? "" : it->second;
}

namespace {

int ParseDomain(const std::string& url) {
  // dds:<domain id>, the ROS_DOMAIN_ID of the robot's network.
  if (url.rfind("dds:", 0) == 0) {
    const std::string n = url.substr(4);
    char* end = nullptr;
    const long d = std::strtol(n.c_str(), &end, 10);
    if (!n.empty() && end && *end == '\0' && d >= 0 && d <= 232) return static_cast<int>(d);
  }
  throw std::runtime_error("url '" + url + "': expected dds:<domain id 0..232> (the robot's ROS_DOMAIN_ID)");
}

// What a topic is read with: best effort matches both kinds of writer; latched topics reliable +
// transient local, so what was published before we joined arrives.
Qos ReaderQos(const std::string& wire) {
  Qos q = DefaultQos(wire);
  if (!q.transient_local) q.reliable = false;
  return q;
}

}  // namespace

Ros2NodeOptions ParseRos2NodeOptions(config::Section& s, const std::string& url, const std::string& node,
                                     bool receives_scans) {
  Ros2NodeOptions o;
  o.dds.domain_id = ParseDomain(url);
  o.dds.node_name = s.GetString("node_name", node,
                                "ros2: the node it is in the ROS 2 graph (ros_discovery_info: `ros2 node list` names "
                                "it; '' = not announced)");
  if (!o.dds.node_name.empty() &&
      o.dds.node_name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_") !=
          std::string::npos)
    s.Fail("node_name", "a ROS 2 node name is letters, digits and underscores");
  o.dds.max_sample_bytes = static_cast<size_t>(
      s.GetDouble("max_message_mb", o.dds.max_sample_bytes / 1048576.0,
                  "ros2: a message larger than this is dropped on receipt (and counted) [MiB]", 0.001, 4096) *
      1048576.0);
  o.dds.config = s.GetString("dds_config", o.dds.config,
                             "ros2: Cyclone DDS configuration (XML or file://…; '' = CYCLONEDDS_URI or its defaults)");
  o.topics.Parse(s, "topics");
  if (receives_scans) {  // a node that only publishes mounts no scan: these keys would be unread
    o.robot_frame = s.GetString("robot_frame", o.robot_frame,
                                "ros2: the robot's frame, whose transform to the scan's frame (/tf_static) is the "
                                "lidar's mount ('' = the frame /odom moves, else base_footprint)");
    o.wait_for_mount_us = static_cast<int64_t>(
        1e6 * s.GetDouble("wait_for_mount_s", o.wait_for_mount_us * 1e-6,
                          "ros2: scans are held back this long waiting for /tf_static's lidar mount [s]", 0.0, 60.0));
  }
  o.frames.map = s.GetString("map_frame", o.frames.map, "ros2: the map's frame");
  o.frames.odom = s.GetString("odom_frame", o.frames.odom, "ros2: the odometry's frame");
  o.frames.robot = s.GetString("base_frame", o.frames.robot, "ros2: the robot's frame (odometry's child)");
  o.frames.lidar = s.GetString("lidar_frame", o.frames.lidar, "ros2: the scans' frame (what a simulated robot says)");
  o.frames.imu = s.GetString("imu_frame", o.frames.imu, "ros2: the IMU's frame");
  o.frames.camera = s.GetString("camera_frame", o.frames.camera, "ros2: the camera image's frame (tag detections)");
  return o;
}

Ros2Node::Ros2Node(Ros2NodeOptions options, const std::vector<std::string>& channels, const msgs::ChannelRoles& roles)
    : o_(std::move(options)),
      roles_(roles),
      dds_(o_.dds),
      decoder_(o_.robot_frame, "ros2"),
      encoder_(o_.topics, o_.frames) {
  auto subscribe = [this](const std::string& topic, const std::string& wire, const std::string& type) {
    const int reader = dds_.AddReader(wire, type, ReaderQos(wire));
    routes_.resize(reader + 1);
    routes_[reader] = {topic, wire, type, MessageDecoder::TypeOf(type, wire)};
    stats_[wire].type = type;
  };
  for (const std::string& c : channels) {
    auto t = o_.types.find(c);
    const std::string type = t != o_.types.end() ? t->second : DefaultRosType(c);
    if (type.empty()) throw std::runtime_error("ros2: channel " + c + " has no ROS 2 message this transport knows");
    subscribe(c, o_.topics.Wire(c), type);
  }
  subscribe("/tf_static", "/tf_static", kTFMessageType);
  decoder_.WaitForMount(o_.wait_for_mount_us);
}

namespace {

// rmw's service topics: "/reset_odometry" → rq/reset_odometryRequest and rr/reset_odometryReply,
// reliable and volatile, keep last 10 (rmw_qos_profile_services_default).
std::string ServiceTopic(const std::string& service, const char* prefix, const char* suffix) {
  return std::string(prefix) + (service.empty() || service.front() != '/' ? "/" + service : service) + suffix;
}
const Qos kServiceQos{10, true, false};

}  // namespace

void Ros2Node::ServeTrigger(const std::string& service, std::function<TriggerResponse()> handler) {
  const int reader = dds_.AddReader(ServiceTopic(service, "rq", "Request"), kTriggerRequestType, kServiceQos, true);
  const int writer = dds_.AddWriter(ServiceTopic(service, "rr", "Reply"), kTriggerResponseType, kServiceQos, true);
  servers_[reader] = {service, writer, std::move(handler)};
  stats_[service].type = "std_srvs/srv/Trigger";
}

std::optional<TriggerResponse> Ros2Node::CallTrigger(const std::string& service, int timeout_ms) {
  const int writer = dds_.AddWriter(ServiceTopic(service, "rq", "Request"), kTriggerRequestType, kServiceQos, true);
  const int reader = dds_.AddReader(ServiceTopic(service, "rr", "Reply"), kTriggerResponseType, kServiceQos, true);
  service_readers_.insert(reader);
  stats_[service].type = "std_srvs/srv/Trigger";
  const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  // Volatile topics: a request sent before the server's reader matched is lost.
  while ((dds_.MatchedReaders(writer) == 0 || dds_.MatchedWriters(reader) == 0) &&
         std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  if (dds_.MatchedReaders(writer) == 0) return std::nullopt;
  const std::vector<uint8_t> request = EncodeTriggerRequest();
  if (!dds_.Write(writer, request.data(), request.size())) return std::nullopt;
  ++stats_[service].published;
  std::optional<TriggerResponse> reply;
  while (!reply && std::chrono::steady_clock::now() < end) {
    dds_.TakeFrom(reader, 20, [&](const DdsParticipant::Sample& s) {
      if (reply) return;
      ++stats_[service].received;
      try {
        reply = DecodeTriggerResponse(s.data, s.size);
      } catch (const std::exception& e) {
        ++stats_[service].rejected;
        stats_[service].last_error = e.what();
      }
    });
  }
  return reply;
}

void Ros2Node::Poll(int timeout_ms, std::vector<Event>* out) {
  dds_.Take(timeout_ms, [&](const DdsParticipant::Sample& s) {
    if (service_readers_.count(s.reader)) return;  // a late reply to a call that gave up
    if (auto server = servers_.find(s.reader); server != servers_.end()) {
      TopicStats& st = stats_[server->second.service];
      ++st.received;
      ServiceHeader header;
      bool with_header = false;
      try {
        with_header = DecodeTriggerRequest(s.data, s.size, &header);
      } catch (const std::exception& e) {
        ++st.rejected;
        st.last_error = e.what();
        return;
      }
      const std::vector<uint8_t> reply = Encode(server->second.handler(), with_header ? &header : nullptr);
      if (dds_.Write(server->second.reply_writer, reply.data(), reply.size())) ++st.published;
      return;
    }
    const Route& r = routes_[s.reader];
    TopicStats& st = stats_[r.wire];
    ++st.received;
    Event ev;
    ev.t_us = s.arrival_us;  // when the receive thread got it (what LCM's recv_utime is)
    ev.channel = r.topic;
    std::string refused, error;
    bool got = false;
    try {
      got =
          decoder_.Decode(r.kind, r.topic, r.wire, s.data, s.size, Serialization::kCdr, ev.t_us, roles_, &ev, &refused);
      if (got && !msgs::IsPlausibleTimeUs(ev.stamp_us)) error = "absurd stamp " + std::to_string(ev.stamp_us) + " µs";
    } catch (const std::exception& e) {  // CdrError names the field and offset
      error = r.type + ": " + e.what();
    }
    if (!refused.empty()) error = "transforms refused: " + refused;
    if (!error.empty()) {
      ++st.rejected;
      st.last_error = error;
      mbot::log::WarnOnce("ros2:rejected:" + r.wire,
                          "ros2: " + r.wire + ": malformed message rejected (" + error + "); further ones are counted");
      return;  // nothing of a rejected message goes on
    }
    if (got && ev.kind != EventKind::kOther) out->push_back(std::move(ev));
  });
}

void Ros2Node::PrepareWriter(const std::string& wire, const std::string& type) {
  if (writers_.count(wire)) return;
  writers_[wire] = dds_.AddWriter(wire, type, DefaultQos(wire));
  writer_types_[wire] = type;
  stats_[wire].type = type;
}

bool Ros2Node::Publish(const Event& event) {
  encoded_.clear();
  if (!encoder_.Encode(event, &encoded_)) return false;
  bool sent = false;
  for (const EncodedMessage& m : encoded_) {
    PrepareWriter(m.topic, m.type);
    if (writer_types_[m.topic] != m.type) {  // one type per topic, as ROS has it
      mbot::log::WarnOnce("ros2:type:" + m.topic, "ros2: " + m.topic + " carries " + writer_types_[m.topic] + "; a " +
                                                      m.type + " for it is not sent");
      continue;
    }
    if (dds_.Write(writers_[m.topic], m.cdr.data(), m.cdr.size())) {
      ++stats_[m.topic].published;
      sent = true;
    } else {
      mbot::log::WarnOnce("ros2:write:" + m.topic, "ros2: writing " + m.topic + " failed");
    }
  }
  return sent;
}

long long Ros2Node::rejected_total() const {
  long long n = dds_.too_large();
  for (const auto& [wire, s] : stats_) n += s.rejected;
  return n;
}

std::vector<std::pair<std::string, std::string>> Ros2Node::Details() const {
  std::vector<std::pair<std::string, std::string>> d;
  for (const auto& [wire, s] : stats_) {
    if (s.rejected > 0) d.push_back({"rejected on " + wire, std::to_string(s.rejected) + " (" + s.last_error + ")"});
  }
  if (dds_.too_large() > 0) d.push_back({"messages too large (dropped)", std::to_string(dds_.too_large())});
  for (auto& kv : decoder_.Details()) d.push_back(std::move(kv));
  return d;
}

namespace {

class Ros2Link : public msgs::LiveLink {
 public:
  Ros2Link(Ros2NodeOptions o, const std::vector<std::string>& channels, const msgs::ChannelRoles& roles,
           const std::string& command_channel, const std::string& reset_odometry_service)
      : topics_(o.topics), node_(std::move(o), channels, roles) {
    node_.PrepareWriter(topics_.Wire(command_channel), kTwistType);  // discovery before the first command
    if (!reset_odometry_service.empty()) {
      // The robot's odometry from zero, as the course's nodes start it (odometry from before the
      // reset that is still queued reads as a robot restart, which SLAM's continuity check takes).
      const std::optional<TriggerResponse> r = node_.CallTrigger(reset_odometry_service, kResetTimeoutMs);
      if (!r) {
        mbot::log::Warn("ros2: " + reset_odometry_service + " did not answer within " +
                        std::to_string(kResetTimeoutMs / 1000) + " s; the robot's odometry was not reset");
      } else {
        (r->success ? mbot::log::Info : mbot::log::Warn)("ros2: " + reset_odometry_service + ": " +
                                                         (r->success ? "" : "failed: ") + r->message);
      }
    }
  }
  void Poll(int timeout_ms, std::vector<Event>* out) override { node_.Poll(timeout_ms, out); }
  bool Publish(const Event& event) override { return node_.Publish(event); }
  long long rejected_total() const override { return node_.rejected_total(); }
  std::string name() const override { return "ros2"; }
  std::string where() const override { return node_.where(); }
  msgs::ChannelInfo Describe(const std::string& channel) const override {
    const std::string wire = topics_.Wire(channel);
    auto it = node_.stats().find(wire);
    return msgs::ChannelInfo{it != node_.stats().end() ? it->second.type : "", "ROS 2 " + wire + " (cdr, DDS)",
                             EventKind::kOther, true};
  }
  std::vector<std::pair<std::string, std::string>> Details() const override { return node_.Details(); }

 private:
  static constexpr int kResetTimeoutMs = 3000;
  msgs::TopicTable topics_;
  Ros2Node node_;
};

}  // namespace

std::unique_ptr<msgs::Source> OpenRos2Live(const msgs::SourceOptions& options) {
  Ros2LiveOptions o = msgs::ExtraOr<Ros2LiveOptions>(options);
  o.node.dds.domain_id = ParseDomain(options.path.empty() ? "dds:0" : options.path);
  return std::make_unique<msgs::LiveSource>(
      std::make_unique<Ros2Link>(o.node, o.live.channels, options.roles, o.live.command_channel,
                                 o.reset_odometry_service),
      o.live, "live ROS 2 (DDS)");
}

namespace {

// `ros2_bridge`: this pipeline on ROS 2 from the robot's side. Every event it sees on a `publish`
// channel goes out as the MBot's message on the robot's topic and QoS (/scan, /odom with odom →
// base_footprint on /tf, the lidar's mount on /tf_static, /imu, /encoders); messages arriving on
// `subscribe` channels (/cmd_vel from the autonomy, and what it publishes for a referee) come in
// validated and are emitted to the later stages and the sink (the simulator), stamped with the
// time of the event being processed. So `config/sim_robot_ros2.ini` is a robot an autonomy process
// cannot tell from a real one.
struct BridgeOptions {
  Ros2NodeOptions node;
  std::vector<std::string> publish = {topics::kLidar, topics::kOdometry, topics::kEncoders, topics::kImu};
  std::vector<std::string> subscribe = {topics::kVelocityCommand};
  std::string reset_odometry_service = "/reset_odometry";  // served as the MBot's firmware does ("" = not)
};

class Ros2BridgeStage : public msgs::Stage {
 public:
  explicit Ros2BridgeStage(BridgeOptions o) : o_(std::move(o)), publish_(o_.publish.begin(), o_.publish.end()) {}

  void Start(const msgs::RunContext& ctx) override {
    bus_ = ctx.bus;
    msgs::ChannelRoles roles;
    roles.reference_pose.clear();  // the pose coming back is the stack's estimate, not a reference
    roles.pose_estimate = {topics::kSlamPose};
    node_ = std::make_unique<Ros2Node>(o_.node, o_.subscribe, roles);
    if (!o_.reset_odometry_service.empty()) {
      // As the MBot's firmware: the odometry pose becomes (0, 0, 0) and counts on from there.
      node_->ServeTrigger(o_.reset_odometry_service, [this] {
        odometry_origin_ = last_odometry_;
        odometry_reset_ = true;
        mbot::log::Info("ros2_bridge: " + o_.reset_odometry_service + ": odometry reset");
        return TriggerResponse{true, "Odometry reset to (0, 0, 0)"};
      });
    }
    mbot::log::Info("ros2_bridge: publishing " + std::to_string(publish_.size()) + " channels on " + node_->where());
  }

  void OnEvent(const Event& input) override {
    const Event* in = &input;
    if (input.kind == EventKind::kOdometry) {
      if (const auto* p = std::get_if<msgs::Pose2D>(&input.payload)) {
        last_odometry_ = *p;
        if (odometry_reset_) {  // the published odometry counts from where it was reset
          reset_copy_ = input;
          reset_copy_.payload = odometry_origin_.Inverse().Compose(*p);
          in = &reset_copy_;
        }
      }
    }
    const Event& ev = *in;
    if (publish_.count(ev.channel) && node_->Publish(ev) && ev.kind == EventKind::kLidar)
      latency_.ScanSent(msgs::WallClockUs());
    got_.clear();
    node_->Poll(0, &got_);
    for (Event& in : got_) {
      if (in.kind == EventKind::kMotorCommand) latency_.CommandReceived(in.t_us);
      in.t_us = ev.t_us;  // into this pipeline's (the simulation's) time
      if (bus_) bus_->Emit(this, in);
    }
  }

  void Finish(const msgs::RunContext& ctx, bool /*interrupted*/) override {
    if (!node_) return;
    if (const std::string l = latency_.Summary(); !l.empty()) {
      mbot::log::Info("ros2_bridge: scan out → command back: " + l);
      latency_.WriteJson(ctx.output_dir + "/loop_latency.json", "ros2");
    }
    std::string counts;
    for (const auto& [wire, s] : node_->stats()) {
      counts += (counts.empty() ? "" : ", ") + wire + " " + std::to_string(s.received) + " in / " +
                std::to_string(s.published) + " out" +
                (s.rejected ? " / " + std::to_string(s.rejected) + " rejected" : "");
    }
    mbot::log::Info("ros2_bridge: " + counts);
  }

 private:
  BridgeOptions o_;
  std::set<std::string> publish_;
  msgs::Bus* bus_ = nullptr;
  std::unique_ptr<Ros2Node> node_;
  std::vector<Event> got_;
  msgs::LoopLatency latency_;
  msgs::Pose2D last_odometry_, odometry_origin_;  // the robot's raw odometry, and where it was last reset
  bool odometry_reset_ = false;
  Event reset_copy_;
};

}  // namespace

msgs::StageType Ros2BridgeStageType() {
  return {
      "ros2_bridge",
      "the robot's side of ROS 2 (DDS): publishes the events it sees on `publish` channels as the MBot's "
      "messages, topics and QoS, and emits the validated messages arriving on `subscribe` channels",
      [](config::Section& s) -> std::unique_ptr<msgs::Stage> {
        BridgeOptions o;
        const std::string url =
            s.GetString("url", "dds:0", "ros2_bridge: dds:<domain id> (the ROS_DOMAIN_ID of the network)");
        o.node = ParseRos2NodeOptions(s, url, "mbot_nav_bridge", true);
        ParseTreeFrames(s, "ros2_bridge", &o.node.frames);  // the robot's side publishes the mount
        o.publish = s.GetList("publish", o.publish, "channels published (what the robot's firmware and lidar publish)");
        o.subscribe = s.GetList("subscribe", o.subscribe, "channels listened to (the autonomy's commands and outputs)");
        o.reset_odometry_service =
            s.GetString("reset_odometry_service", o.reset_odometry_service,
                        "ros2_bridge: the std_srvs/Trigger service that zeroes the published odometry, as the "
                        "MBot's firmware serves it ('' = none)");
        return std::make_unique<Ros2BridgeStage>(o);
      }};
}

namespace {

class Ros2Output : public msgs::Output {
 public:
  explicit Ros2Output(Ros2NodeOptions o) : o_(std::move(o)) {}
  void Open(const msgs::RunContext& /*context*/) override {
    node_ = std::make_unique<Ros2Node>(o_, std::vector<std::string>{}, msgs::ChannelRoles{});
    mbot::log::Info("output ros2: publishing on " + node_->where() + " as node /" + o_.dds.node_name);
  }
  void Send(const Event& event) override {
    if (node_ && !node_->Publish(event)) ++unsent_[msgs::ToString(event.kind)];
  }
  void Close(bool /*interrupted*/) override {
    if (!node_) return;
    std::string counts, unsent;
    for (const auto& [wire, st] : node_->stats()) {
      if (st.published > 0) counts += (counts.empty() ? "" : ", ") + wire + " " + std::to_string(st.published);
    }
    for (const auto& [kind, n] : unsent_) unsent += (unsent.empty() ? "" : ", ") + kind + " " + std::to_string(n);
    mbot::log::Info("output ros2: published " + (counts.empty() ? std::string("nothing") : counts) +
                    (unsent.empty() ? "" : "; no ROS 2 message for " + unsent));
    node_.reset();
  }

 private:
  Ros2NodeOptions o_;
  std::unique_ptr<Ros2Node> node_;
  std::map<std::string, long long> unsent_;
};

}  // namespace

msgs::OutputType Ros2OutputType() {
  msgs::OutputType t;
  t.name = "ros2";
  t.doc =
      "publishes the run's events over DDS as the MBot's ROS 2 messages, topics and QoS (url dds:<domain>): a "
      "replay or a simulation seen in RViz or Foxglove over ROS 2; /map and /tf_static transient local";
  t.create = [](config::Section& s) -> std::unique_ptr<msgs::Output> {
    const std::string url = s.GetString("url", "dds:0", "ros2: dds:<domain id> (the ROS_DOMAIN_ID of the network)");
    Ros2NodeOptions o = ParseRos2NodeOptions(s, url, "mbot_nav_replay", false);
    ParseTreeFrames(s, "ros2", &o.frames);
    return std::make_unique<Ros2Output>(std::move(o));
  };
  return t;
}

}  // namespace mbot::ros2
