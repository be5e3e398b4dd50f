#include "bag_recorder.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/ros2/definitions.hpp"

namespace mbot::ros2 {

using msgs::Event;
using msgs::EventKind;

namespace {

// rosbag2's QoS as Jazzy writes it (metadata version 9: policies by name; durations "infinite").
std::string QosYaml(const BagQos& q, const std::string& indent) {
  const std::string inf = "\n" + indent + "    sec: 9223372036\n" + indent + "    nsec: 854775807";
  std::ostringstream o;
  o << indent << "- history: keep_last\n"
    << indent << "  depth: " << q.depth << "\n"
    << indent << "  reliability: " << (q.reliable ? "reliable" : "best_effort") << "\n"
    << indent << "  durability: " << (q.transient_local ? "transient_local" : "volatile") << "\n"
    << indent << "  deadline:" << inf << "\n"
    << indent << "  lifespan:" << inf << "\n"
    << indent << "  liveliness: automatic\n"
    << indent << "  liveliness_lease_duration:" << inf << "\n"
    << indent << "  avoid_ros_namespace_conventions: false";
  return o.str();
}

}  // namespace

Qos DefaultQos(const std::string& topic) {
  // The MBot's (mbot_ros2_ws, mbot_firmware_ros): sensors best effort from the firmware, the lidar
  // and the autonomy's topics reliable, latched ones transient local.
  if (topic == "/tf_static" || topic == "/map") return {1, true, true};
  if (topic == "/imu" || topic == "/encoders" || topic == "/motor_vel") return {10, false, false};
  if (topic == "/tf") return {100, true, false};
  return {10, true, false};
}

BagRecorder::BagRecorder(BagRecorderOptions options)
    : o_(std::move(options)), encoder_(o_.topics, [this] {
        Frames f = o_.tree;
        f.map = o_.map_frame, f.odom = o_.odom_frame, f.robot = o_.robot_frame;
        f.lidar = o_.lidar_frame, f.imu = o_.imu_frame, f.camera = o_.camera_frame;
        return f;
      }()) {}
BagRecorder::~BagRecorder() = default;

void BagRecorder::Open(const msgs::RunContext& ctx) {
  dir_ = ctx.output_dir;
  writer_ = std::make_unique<McapWriter>(dir_ + "/" + o_.file, McapWriterOptions{"ros2", "mbot_nav", o_.compression});
}

uint16_t BagRecorder::Channel(const std::string& topic, const std::string& type) {
  auto it = channels_.find(topic);
  if (it != channels_.end()) {
    if (it->second.type != type) return 0;  // one type per topic, as ROS has it
    return it->second.id;
  }
  auto s = schemas_.find(type);
  if (s == schemas_.end()) s = schemas_.emplace(type, writer_->AddSchema(type, "ros2msg", Definition(type))).first;
  const BagQos q = DefaultQos(topic);
  const uint16_t id = writer_->AddChannel(s->second, topic, "cdr", {{"offered_qos_profiles", QosYaml(q, "")}});
  channels_[topic] = {id, type, q};
  return id;
}

void BagRecorder::Put(const std::string& topic, const std::string& type, int64_t t_us,
                      const std::vector<uint8_t>& cdr) {
  const uint16_t id = Channel(topic, type);
  if (id == 0) {
    ++skipped_[topic + " (a second type, " + type + ")"];
    return;
  }
  const uint64_t t_ns = static_cast<uint64_t>(std::max<int64_t>(0, t_us)) * 1000;
  writer_->Write(id, t_ns, t_ns, cdr);
}

void BagRecorder::Send(const Event& event) {
  if (!writer_) return;
  encoded_.clear();
  if (!encoder_.Encode(event, &encoded_)) ++skipped_[msgs::ToString(event.kind)];
  for (const EncodedMessage& m : encoded_) Put(m.topic, m.type, m.t_us, m.cdr);
}

std::string BagRecorder::MetadataYaml(bool for_file) const {
  const uint64_t start = writer_->start_time_ns(), end = writer_->end_time_ns();
  const std::string in = for_file ? "  " : "";
  std::ostringstream y;
  if (for_file) y << "rosbag2_bagfile_information:\n";
  y << in << "version: 9\n"
    << in << "storage_identifier: mcap\n"
    << in << "duration:\n"
    << in << "  nanoseconds: " << (end - start) << "\n"
    << in << "starting_time:\n"
    << in << "  nanoseconds_since_epoch: " << start << "\n"
    << in << "message_count: " << writer_->messages() << "\n"
    << in << "topics_with_message_count:\n";
  for (const auto& [topic, c] : channels_) {
    y << in << "  - topic_metadata:\n"
      << in << "      name: " << topic << "\n"
      << in << "      type: " << c.type << "\n"
      << in << "      serialization_format: cdr\n"
      << in << "      offered_qos_profiles:\n"
      << QosYaml(c.qos, in + "        ") << "\n"
      << in << "      type_description_hash: \"\"\n"
      << in << "    message_count: " << writer_->channel_counts().at(c.id) << "\n";
  }
  y << in << "compression_format: \"\"\n"
    << in << "compression_mode: \"\"\n"
    << in << "relative_file_paths:\n"
    << in << "  - " << o_.file << "\n"
    << in << "files:\n"
    << in << "  - path: " << o_.file << "\n"
    << in << "    starting_time:\n"
    << in << "      nanoseconds_since_epoch: " << start << "\n"
    << in << "    duration:\n"
    << in << "      nanoseconds: " << (end - start) << "\n"
    << in << "    message_count: " << writer_->messages() << "\n"
    << in << "custom_data: ~\n"
    << in << "ros_distro: jazzy\n";
  return y.str();
}

void BagRecorder::Close(bool interrupted) {
  if (!writer_) return;
  writer_->AddMetadata("rosbag2", {{"serialized_metadata", MetadataYaml(false)}, {"ROS_DISTRO", "jazzy"}});
  writer_->Close();
  // metadata.yaml beside it, whole or not at all.
  const std::string meta = dir_ + "/metadata.yaml";
  {
    std::ofstream out(meta + ".tmp", std::ios::trunc);
    out << MetadataYaml(true);
    if (!out) throw std::runtime_error(meta + ".tmp: cannot be written");
  }
  if (std::rename((meta + ".tmp").c_str(), meta.c_str()) != 0) throw std::runtime_error(meta + ": cannot be written");
  std::string skipped;
  for (const auto& [what, n] : skipped_) skipped += (skipped.empty() ? "" : ", ") + what + " " + std::to_string(n);
  mbot::log::Info(
      "output rosbag2: " + std::to_string(writer_->messages()) + " messages on " + std::to_string(channels_.size()) +
      " topics to " + dir_ + "/" + o_.file + " (+ metadata.yaml)" +
      (interrupted ? " (interrupted: everything up to the stop)" : "") +
      (encoder_.binned() ? "; " + std::to_string(encoder_.binned()) + " scans binned onto uniform angles" : "") +
      (skipped.empty() ? "" : "; no ROS 2 message for " + skipped));
  writer_.reset();
}

BagRecorderOptions ParseBagRecorderOptions(config::Section& s) {
  BagRecorderOptions o;
  o.file = s.GetString("file", o.file, "rosbag2: the MCAP file, in the output folder (metadata.yaml beside it)");
  if (o.file.empty() || o.file.find('/') != std::string::npos) s.Fail("file", "must be a file name, not a path");
  o.compression = s.GetChoice("compression", o.compression, {"zstd", "none"}, "rosbag2: chunk compression");
  if (o.compression == "none") o.compression = "";
  o.topics.Parse(s, "rename");
  o.map_frame = s.GetString("map_frame", o.map_frame, "rosbag2: the map's frame");
  o.odom_frame = s.GetString("odom_frame", o.odom_frame, "rosbag2: the odometry's frame");
  o.robot_frame = s.GetString("robot_frame", o.robot_frame, "rosbag2: the robot's frame (odometry's child)");
  o.lidar_frame = s.GetString("lidar_frame", o.lidar_frame, "rosbag2: the scans' frame");
  o.imu_frame = s.GetString("imu_frame", o.imu_frame, "rosbag2: the IMU's frame");
  o.camera_frame = s.GetString("camera_frame", o.camera_frame, "rosbag2: the camera image's frame (tag detections)");
  ParseTreeFrames(s, "rosbag2", &o.tree);
  return o;
}

}  // namespace mbot::ros2
