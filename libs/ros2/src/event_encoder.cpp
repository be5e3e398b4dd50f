#include "event_encoder.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>

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

}  // namespace

void ParseTreeFrames(config::Section& s, const std::string& what, Frames* f) {
  f->base_link = s.GetString("base_link_frame", f->base_link,
                             what +
                                 ": the frame between the robot's and the lidar's on /tf_static, as the MBot's "
                                 "robot_state_publisher has it ('' = the lidar straight from the robot's frame)");
  f->base_link_z_m =
      s.GetDouble("base_link_z_m", f->base_link_z_m, what + ": base_link above the robot's frame [m]", -10.0, 10.0);
  f->lidar_z_m = s.GetDouble("lidar_z_m", f->lidar_z_m, what + ": the lidar above base_link [m]", -10.0, 10.0);
}

bool EventEncoder::Encode(const Event& event, std::vector<EncodedMessage>* out) {
  out_ = out;
  const bool any = msgs::Visit(event, *this);
  out_ = nullptr;
  return any;
}

void EventEncoder::Put(std::string topic, const char* type, int64_t t_us, std::vector<uint8_t> cdr) {
  out_->push_back({std::move(topic), type, t_us, std::move(cdr)});
}

std::string EventEncoder::TopicFor(const Event& ev) const {
  namespace topics = msgs::topics;
  // Poses: the kind says which topic (a log's staff SLAM_POSE is a reference, ours the estimate).
  switch (ev.kind) {
    case EventKind::kPoseEstimate: return topics_.Wire(topics::kSlamPose);
    case EventKind::kReferencePose: return "/reference_pose";
    case EventKind::kGroundTruth: return topics_.Wire(topics::kTruePose);
    case EventKind::kGoal: return "/goal_pose";
    default: break;
  }
  const std::string wire = topics_.Wire(ev.channel);
  if (!wire.empty() && wire.front() == '/') return wire;
  // A channel with no ROS name (an older generation's ODOMETRY, MBOT_MOTOR_COMMAND): the kind's topic.
  switch (ev.kind) {
    case EventKind::kLidar: return topics_.Wire(topics::kLidar);
    case EventKind::kOdometry: return topics_.Wire(topics::kOdometry);
    case EventKind::kImu: return topics_.Wire(topics::kImu);
    case EventKind::kMotorCommand: return topics_.Wire(topics::kVelocityCommand);
    case EventKind::kMap: return topics_.Wire(topics::kSlamMap);
    case EventKind::kParticles: return topics_.Wire(topics::kSlamParticles);
    case EventKind::kPath: return topics_.Wire(topics::kPath);
    case EventKind::kEncoders: return topics_.Wire(topics::kEncoders);
    case EventKind::kWheelSpeed: return topics_.Wire(topics::kMotorVelocity);
    case EventKind::kFrontiers: return topics_.Wire(topics::kFrontiers);
    case EventKind::kMissionStatus: return topics_.Wire(topics::kMissionStatus);
    case EventKind::kTagSightings: return topics_.Wire(topics::kTags);
    default: break;
  }
  std::string name = "/";  // else "/" and the channel's name in lower case (a valid ROS name)
  for (char c : ev.channel) name += std::isalnum(static_cast<unsigned char>(c)) ? char(std::tolower(c)) : '_';
  return name;
}

bool EventEncoder::Lidar(const Event& ev, const msgs::LidarScan& scan) {
  const size_t n = scan.ranges_m.size();
  if (n < 2 || scan.angles_rad.size() != n) return false;
  if (!mount_written_ || mount_.x != scan.sensor_pose.x || mount_.y != scan.sensor_pose.y ||
      mount_.theta != scan.sensor_pose.theta) {
    mount_ = scan.sensor_pose;
    mount_written_ = true;
    TFMessage tf;
    TransformStamped t;
    t.header = {StampOf(ev.t_us), frames_.robot};
    const bool via_base_link = !frames_.base_link.empty() && frames_.base_link != frames_.robot;
    if (via_base_link) {
      t.child_frame_id = frames_.base_link;
      t.transform.translation = {0.0, 0.0, frames_.base_link_z_m};
      tf.transforms.push_back(t);
      t.header.frame_id = frames_.base_link;
    }
    t.child_frame_id = frames_.lidar;
    t.transform = TransformOf(mount_);
    t.transform.translation.z = frames_.lidar_z_m + (via_base_link ? 0.0 : frames_.base_link_z_m);
    tf.transforms.push_back(t);
    Put("/tf_static", kTFMessageType, ev.t_us, ros2::Encode(tf));
  }
  LaserScan m;
  m.header = {StampOf(ev.t_us), frames_.lidar};
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
  Put(TopicFor(ev), kLaserScanType, ev.t_us, ros2::Encode(m));
  return true;
}

bool EventEncoder::Pose(const Event& ev, const msgs::Pose2D& p) {
  const std::string topic = TopicFor(ev);
  switch (ev.kind) {
    case EventKind::kOdometry: {
      Odometry m;
      m.header = {StampOf(ev.t_us), frames_.odom};
      m.child_frame_id = frames_.robot;
      m.pose = PoseOf(p);
      Put(topic, kOdometryType, ev.t_us, ros2::Encode(m));
      TFMessage tf;
      tf.transforms.push_back({{StampOf(ev.t_us), frames_.odom}, frames_.robot, TransformOf(p)});
      Put("/tf", kTFMessageType, ev.t_us, ros2::Encode(tf));
      odom_ = p;
      have_odom_ = true;
      return true;
    }
    case EventKind::kPoseEstimate: {
      Put(topic, kPoseStampedType, ev.t_us, ros2::Encode(PoseStamped{{StampOf(ev.t_us), frames_.map}, PoseOf(p)}));
      if (have_odom_) {  // map → odom, so that map → odom → base_footprint is the estimate
        TFMessage tf;
        tf.transforms.push_back(
            {{StampOf(ev.t_us), frames_.map}, frames_.odom, TransformOf(p.Compose(odom_.Inverse()))});
        Put("/tf", kTFMessageType, ev.t_us, ros2::Encode(tf));
      }
      return true;
    }
    case EventKind::kGroundTruth:
    case EventKind::kReferencePose:
    case EventKind::kGoal:
      Put(topic, kPoseStampedType, ev.t_us, ros2::Encode(PoseStamped{{StampOf(ev.t_us), frames_.map}, PoseOf(p)}));
      return true;
    default: return false;
  }
}

bool EventEncoder::ImuReading(const Event& ev, const msgs::Imu& imu) {
  Imu m;
  m.header = {StampOf(ev.t_us), frames_.imu};
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
  Put(TopicFor(ev), kImuType, ev.t_us, ros2::Encode(m));
  return true;
}

bool EventEncoder::Motors(const Event& ev, const msgs::MotorCommand& c) {
  if (ev.kind != EventKind::kMotorCommand || c.kind != msgs::MotorCommand::Kind::kVelocity) return false;
  Twist t;
  t.linear.x = c.velocity.v_m_s;
  t.angular.z = c.velocity.w_rad_s;
  Put(TopicFor(ev), kTwistType, ev.t_us, ros2::Encode(t));
  return true;
}

bool EventEncoder::Map(const Event& ev, const msgs::OccupancyGrid& g) {
  OccupancyGrid m;
  m.header = {StampOf(ev.t_us), frames_.map};
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
  Put(TopicFor(ev), kOccupancyGridType, ev.t_us, ros2::Encode(m));
  return true;
}

bool EventEncoder::PathPoses(const Event& ev, const msgs::Path& p) {
  Path m;
  m.header = {StampOf(ev.t_us), frames_.map};
  for (const msgs::Pose2D& q : p.poses) m.poses.push_back({m.header, PoseOf(q)});
  Put(TopicFor(ev), kPathType, ev.t_us, ros2::Encode(m));
  return true;
}

bool EventEncoder::ParticleSet(const Event& ev, const msgs::Particles& p) {
  PoseArray m;
  m.header = {StampOf(ev.t_us), frames_.map};
  for (const msgs::Pose2D& q : p.poses) m.poses.push_back(PoseOf(q));
  Put(TopicFor(ev), kPoseArrayType, ev.t_us, ros2::Encode(m));
  return true;
}

bool EventEncoder::Encoders(const Event& ev, const msgs::EncoderTicks& e) {
  ros2::Encoders m;
  m.stamp = StampOf(ev.stamp_us ? ev.stamp_us : ev.t_us);
  m.ticks = {e.left_ticks, e.right_ticks, 0};
  m.delta_ticks = {e.left_delta, e.right_delta, 0};
  m.delta_time = static_cast<int32_t>(e.delta_time_us);
  Put(TopicFor(ev), kEncodersType, ev.t_us, ros2::Encode(m));
  return true;
}

bool EventEncoder::Wheels(const Event& ev, const msgs::WheelSpeeds& w) {
  if (ev.kind != EventKind::kWheelSpeed) return false;
  ros2::MotorVelocity m;
  m.velocity = {static_cast<float>(w.left_rad_s), static_cast<float>(w.right_rad_s), 0.0f};
  Put(TopicFor(ev), kMotorVelocityType, ev.t_us, ros2::Encode(m));
  return true;
}

bool EventEncoder::FrontierSet(const Event& ev, const msgs::Frontiers& f) {
  // One POINTS marker per region (a DELETEALL first, so regions that closed disappear in RViz).
  MarkerArray m;
  Marker clear;
  clear.header = {StampOf(ev.t_us), frames_.map};
  clear.ns = "frontiers";
  clear.action = Marker::kDeleteAll;
  m.markers.push_back(clear);
  int id = 0;
  for (const msgs::FrontierRegion& r : f.regions) {
    Marker k;
    k.header = clear.header;
    k.ns = "frontiers";
    k.id = id++;
    k.type = Marker::kPoints;
    k.action = Marker::kAdd;
    k.scale = {f.cell_size_m, f.cell_size_m, 0.0};
    k.color = {1.0f, 0.5f, 0.0f, 1.0f};
    for (const msgs::Pose2D& c : r.cells) k.points.push_back({c.x, c.y, 0.0});
    m.markers.push_back(std::move(k));
  }
  Put(TopicFor(ev), kMarkerArrayType, ev.t_us, ros2::Encode(m));
  return true;
}

bool EventEncoder::Mission(const Event& ev, const msgs::MissionStatus& s) {
  String m{std::string(msgs::ToString(s.state)) + (s.detail.empty() ? "" : ": " + s.detail)};
  Put(TopicFor(ev), kStringType, ev.t_us, ros2::Encode(m));
  return true;
}

std::optional<msgs::MissionStatus> ParseMissionState(const std::string& text) {
  const size_t colon = text.find(':');
  const std::optional<msgs::MissionState> state = msgs::MissionStateFromString(text.substr(0, colon));
  if (!state) return std::nullopt;
  msgs::MissionStatus s;
  s.state = *state;
  if (colon != std::string::npos) s.detail = text.substr(std::min(text.size(), colon + 2));
  return s;
}

bool EventEncoder::Tags(const Event& ev, const msgs::TagSightings& tags) {
  // apriltag_ros's two outputs: the detections in the image, and each tag's pose on /tf (child
  // frame "<family>:<id>", as apriltag_ros names it, in the camera's optical frame).
  AprilTagDetectionArray m;
  m.header = {StampOf(ev.t_us), frames_.camera};
  TFMessage tf;
  for (const msgs::TagSighting& t : tags.tags) {
    AprilTagDetection d;
    d.family = t.family;
    d.id = t.id;
    d.hamming = t.hamming;
    d.decision_margin = static_cast<float>(t.margin);
    d.centre = t.centre_px;
    d.corners = t.corners_px;
    d.homography = t.homography;
    m.detections.push_back(std::move(d));
    TransformStamped p;
    p.header = m.header;
    p.child_frame_id = (t.family.empty() ? std::string("tag") : t.family) + ":" + std::to_string(t.id);
    p.transform.translation = {t.x_m, t.y_m, t.z_m};
    p.transform.rotation = {t.qx, t.qy, t.qz, t.qw};
    tf.transforms.push_back(std::move(p));
  }
  Put(TopicFor(ev), kAprilTagDetectionArrayType, ev.t_us, ros2::Encode(m));
  if (!tf.transforms.empty()) Put("/tf", kTFMessageType, ev.t_us, ros2::Encode(tf));
  return true;
}

}  // namespace mbot::ros2
