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

Time StampOf(int64_t t_us) {
  Time t;
  const int64_t us = std::max<int64_t>(0, t_us);
  t.sec = static_cast<int32_t>(us / 1'000'000);
  t.nanosec = static_cast<uint32_t>((us % 1'000'000) * 1000);
  return t;
}
Pose PoseOf(const msgs::Pose2D& p) {
  Pose out;
  out.position = {p.x, p.y, 0.0};
  out.orientation = FromYaw(p.theta);
  return out;
}
Transform TransformOf(const msgs::Pose2D& p) { return {{p.x, p.y, 0.0}, FromYaw(p.theta)}; }

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

BagQos DefaultQos(const std::string& topic) {
  // The MBot's (mbot_ros2_ws, mbot_firmware_ros): sensors best effort from the firmware, the lidar
  // and the autonomy's topics reliable, latched ones transient local.
  if (topic == "/tf_static" || topic == "/map") return {1, true, true};
  if (topic == "/imu" || topic == "/encoders" || topic == "/motor_vel") return {10, false, false};
  if (topic == "/tf") return {100, true, false};
  return {10, true, false};
}

BagRecorder::BagRecorder(BagRecorderOptions options) : o_(std::move(options)) {}
BagRecorder::~BagRecorder() = default;

void BagRecorder::Open(const msgs::RunContext& ctx) {
  dir_ = ctx.output_dir;
  writer_ = std::make_unique<McapWriter>(dir_ + "/" + o_.file, McapWriterOptions{"ros2", "mbot_nav", o_.compression});
}

std::string BagRecorder::TopicFor(const Event& ev) const {
  namespace topics = msgs::topics;
  // Poses: the kind says which topic (a log's staff SLAM_POSE is a reference, ours the estimate).
  switch (ev.kind) {
    case EventKind::kPoseEstimate: return o_.topics.Wire(topics::kSlamPose);
    case EventKind::kReferencePose: return "/reference_pose";
    case EventKind::kGroundTruth: return o_.topics.Wire(topics::kTruePose);
    case EventKind::kGoal: return "/goal_pose";
    default: break;
  }
  const std::string wire = o_.topics.Wire(ev.channel);
  if (!wire.empty() && wire.front() == '/') return wire;
  // A channel with no ROS name (an older generation's ODOMETRY, MBOT_MOTOR_COMMAND): the kind's topic.
  switch (ev.kind) {
    case EventKind::kLidar: return o_.topics.Wire(topics::kLidar);
    case EventKind::kOdometry: return o_.topics.Wire(topics::kOdometry);
    case EventKind::kImu: return o_.topics.Wire(topics::kImu);
    case EventKind::kMotorCommand: return o_.topics.Wire(topics::kVelocityCommand);
    case EventKind::kMap: return o_.topics.Wire(topics::kSlamMap);
    case EventKind::kParticles: return o_.topics.Wire(topics::kSlamParticles);
    case EventKind::kPath: return o_.topics.Wire(topics::kPath);
    default: break;
  }
  std::string name = "/";  // else "/" and the channel's name in lower case (a valid ROS name)
  for (char c : ev.channel) name += std::isalnum(static_cast<unsigned char>(c)) ? char(std::tolower(c)) : '_';
  return name;
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
  if (!msgs::Visit(event, *this)) ++skipped_[msgs::ToString(event.kind)];
}

bool BagRecorder::Lidar(const Event& ev, const msgs::LidarScan& scan) {
  const size_t n = scan.ranges_m.size();
  if (n < 2 || scan.angles_rad.size() != n) return false;
  if (!mount_written_ || mount_.x != scan.sensor_pose.x || mount_.y != scan.sensor_pose.y ||
      mount_.theta != scan.sensor_pose.theta) {
    mount_ = scan.sensor_pose;
    mount_written_ = true;
    TFMessage tf;
    TransformStamped t;
    t.header = {StampOf(ev.t_us), o_.robot_frame};
    t.child_frame_id = o_.lidar_frame;
    t.transform = TransformOf(mount_);
    tf.transforms.push_back(t);
    Put("/tf_static", kTFMessageType, ev.t_us, Encode(tf));
  }
  LaserScan m;
  m.header = {StampOf(ev.t_us), o_.lidar_frame};
  float hi = scan.max_range_m;
  for (float r : scan.ranges_m) {
    if (std::isfinite(r) && r > hi && scan.max_range_m <= 0) hi = r;
  }
  m.range_min = 0.0f;
  m.range_max = hi > 0 ? hi : 1.0f;
  const float no_return = INFINITY;  // REP 117: nothing within range
  // Uniform angles go as they are; others (a turning lidar's own angles) are binned onto n uniform
  // angles over the turn, as sllidar does, the nearest return per bin and NaN for an empty bin.
  const double a0 = scan.angles_rad.front(), inc = (double(scan.angles_rad.back()) - a0) / double(n - 1);
  bool uniform = inc != 0.0 && std::isfinite(inc);
  for (size_t i = 0; uniform && i < n; ++i) uniform = std::abs(scan.angles_rad[i] - (a0 + i * inc)) < std::abs(inc) / 4;
  if (uniform) {
    m.angle_min = static_cast<float>(a0);
    m.angle_max = scan.angles_rad.back();
    m.angle_increment = static_cast<float>(inc);
    m.ranges.resize(n);
    for (size_t i = 0; i < n; ++i) {
      const float r = scan.ranges_m[i];
      m.ranges[i] = std::isfinite(r) && r > 0 ? r : no_return;
    }
    if (scan.beam_times_us.size() == n && scan.beam_times_us.back() > scan.beam_times_us.front()) {
      m.time_increment = float((scan.beam_times_us.back() - scan.beam_times_us.front()) * 1e-6 / double(n - 1));
      m.scan_time = m.time_increment * float(n);
    }
    if (scan.intensities.size() == n) m.intensities = scan.intensities;
  } else {
    const double step = 2 * M_PI / double(n);
    m.angle_min = static_cast<float>(-M_PI);
    m.angle_increment = static_cast<float>(step);
    m.angle_max = static_cast<float>(-M_PI + step * double(n - 1));
    m.ranges.assign(n, NAN);
    for (size_t i = 0; i < n; ++i) {
      const double a = std::remainder(double(scan.angles_rad[i]), 2 * M_PI);
      const size_t b = static_cast<size_t>(std::llround((a + M_PI) / step)) % n;
      const float r = scan.ranges_m[i];
      const float v = std::isfinite(r) && r > 0 ? r : no_return;
      if (std::isnan(m.ranges[b]) || v < m.ranges[b]) m.ranges[b] = v;
    }
    ++binned_;
  }
  Put(TopicFor(ev), kLaserScanType, ev.t_us, Encode(m));
  return true;
}

bool BagRecorder::Pose(const Event& ev, const msgs::Pose2D& p) {
  const std::string topic = TopicFor(ev);
  switch (ev.kind) {
    case EventKind::kOdometry: {
      Odometry m;
      m.header = {StampOf(ev.t_us), o_.odom_frame};
      m.child_frame_id = o_.robot_frame;
      m.pose = PoseOf(p);
      Put(topic, kOdometryType, ev.t_us, Encode(m));
      TFMessage tf;
      tf.transforms.push_back({{StampOf(ev.t_us), o_.odom_frame}, o_.robot_frame, TransformOf(p)});
      Put("/tf", kTFMessageType, ev.t_us, Encode(tf));
      odom_ = p;
      have_odom_ = true;
      return true;
    }
    case EventKind::kPoseEstimate: {
      Put(topic, kPoseStampedType, ev.t_us, Encode(PoseStamped{{StampOf(ev.t_us), o_.map_frame}, PoseOf(p)}));
      if (have_odom_) {  // map → odom, so that map → odom → base_footprint is the estimate
        TFMessage tf;
        tf.transforms.push_back(
            {{StampOf(ev.t_us), o_.map_frame}, o_.odom_frame, TransformOf(p.Compose(odom_.Inverse()))});
        Put("/tf", kTFMessageType, ev.t_us, Encode(tf));
      }
      return true;
    }
    case EventKind::kGroundTruth:
    case EventKind::kReferencePose:
    case EventKind::kGoal:
      Put(topic, kPoseStampedType, ev.t_us, Encode(PoseStamped{{StampOf(ev.t_us), o_.map_frame}, PoseOf(p)}));
      return true;
    default: return false;
  }
}

bool BagRecorder::ImuReading(const Event& ev, const msgs::Imu& imu) {
  Imu m;
  m.header = {StampOf(ev.t_us), o_.imu_frame};
  if (imu.has_angles) {
    const double r = imu.angles_rpy_rad[0] / 2, pi = imu.angles_rpy_rad[1] / 2, y = imu.angles_rpy_rad[2] / 2;
    m.orientation = {std::sin(r) * std::cos(pi) * std::cos(y) - std::cos(r) * std::sin(pi) * std::sin(y),
                     std::cos(r) * std::sin(pi) * std::cos(y) + std::sin(r) * std::cos(pi) * std::sin(y),
                     std::cos(r) * std::cos(pi) * std::sin(y) - std::sin(r) * std::sin(pi) * std::cos(y),
                     std::cos(r) * std::cos(pi) * std::cos(y) + std::sin(r) * std::sin(pi) * std::sin(y)};
  } else {
    m.orientation_covariance[0] = -1.0;  // sensor_msgs/Imu: no orientation estimate
  }
  m.angular_velocity = {imu.gyro_rad_s[0], imu.gyro_rad_s[1], imu.gyro_rad_s[2]};
  m.linear_acceleration = {imu.accel_m_s2[0], imu.accel_m_s2[1], imu.accel_m_s2[2]};
  Put(TopicFor(ev), kImuType, ev.t_us, Encode(m));
  return true;
}

bool BagRecorder::Motors(const Event& ev, const msgs::MotorCommand& c) {
  if (ev.kind != EventKind::kMotorCommand || c.kind != msgs::MotorCommand::Kind::kVelocity) return false;
  Twist t;
  t.linear.x = c.velocity.v_m_s;
  t.angular.z = c.velocity.w_rad_s;
  Put(TopicFor(ev), kTwistType, ev.t_us, Encode(t));
  return true;
}

bool BagRecorder::Map(const Event& ev, const msgs::OccupancyGrid& g) {
  OccupancyGrid m;
  m.header = {StampOf(ev.t_us), o_.map_frame};
  m.info.map_load_time = StampOf(ev.t_us);
  m.info.resolution = static_cast<float>(g.resolution());
  m.info.width = static_cast<uint32_t>(g.width());
  m.info.height = static_cast<uint32_t>(g.height());
  m.info.origin.position = {g.origin_x(), g.origin_y(), 0.0};
  m.data.resize(g.cells().size());
  // Log-odds to the map_server's trinary values: occupied 100, free 0, unknown -1.
  for (size_t i = 0; i < m.data.size(); ++i) {
    const int8_t l = g.cells()[i];
    m.data[i] = l > 0 ? 100 : (l < 0 ? 0 : -1);
  }
  Put(TopicFor(ev), kOccupancyGridType, ev.t_us, Encode(m));
  return true;
}

bool BagRecorder::PathPoses(const Event& ev, const msgs::Path& p) {
  Path m;
  m.header = {StampOf(ev.t_us), o_.map_frame};
  for (const msgs::Pose2D& q : p.poses) m.poses.push_back({m.header, PoseOf(q)});
  Put(TopicFor(ev), kPathType, ev.t_us, Encode(m));
  return true;
}

bool BagRecorder::ParticleSet(const Event& ev, const msgs::Particles& p) {
  PoseArray m;
  m.header = {StampOf(ev.t_us), o_.map_frame};
  for (const msgs::Pose2D& q : p.poses) m.poses.push_back(PoseOf(q));
  Put(TopicFor(ev), kPoseArrayType, ev.t_us, Encode(m));
  return true;
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
  mbot::log::Info("output rosbag2: " + std::to_string(writer_->messages()) + " messages on " +
                  std::to_string(channels_.size()) + " topics to " + dir_ + "/" + o_.file + " (+ metadata.yaml)" +
                  (interrupted ? " (interrupted: everything up to the stop)" : "") +
                  (binned_ ? "; " + std::to_string(binned_) + " scans binned onto uniform angles" : "") +
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
  return o;
}

}  // namespace mbot::ros2
