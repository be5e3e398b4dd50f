#include "message_decoder.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "event_encoder.hpp"
#include "mbot/common/log.hpp"

namespace mbot::ros2 {

using msgs::Event;
using msgs::EventKind;
using msgs::Pose2D;

namespace {

Quaternion Multiply(const Quaternion& a, const Quaternion& b) {
  return {a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y, a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
          a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w, a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z};
}
}  // namespace

Vector3 Rotate(const Quaternion& q, const Vector3& v) {
  const Quaternion p{v.x, v.y, v.z, 0.0};
  const Quaternion r = Multiply(Multiply(q, p), {-q.x, -q.y, -q.z, q.w});
  return {r.x, r.y, r.z};
}
// a ∘ b: b expressed in a's frame, mapped to a's parent.
Transform Compose(const Transform& a, const Transform& b) {
  const Vector3 t = Rotate(a.rotation, b.translation);
  return {{a.translation.x + t.x, a.translation.y + t.y, a.translation.z + t.z}, Multiply(a.rotation, b.rotation)};
}
Transform Inverse(const Transform& t) {
  const Quaternion inv{-t.rotation.x, -t.rotation.y, -t.rotation.z, t.rotation.w};
  return {Rotate(inv, {-t.translation.x, -t.translation.y, -t.translation.z}), inv};
}

namespace {

Quaternion Normalised(const Quaternion& q) {
  const double n = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  return n > 0 && std::isfinite(n) ? Quaternion{q.x / n, q.y / n, q.z / n, q.w / n} : Quaternion{};
}
bool Finite(const Transform& t) {
  for (double v :
       {t.translation.x, t.translation.y, t.translation.z, t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w}) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

int64_t StampUs(const Time& t) { return int64_t(t.sec) * 1'000'000 + int64_t(t.nanosec / 1000); }

Pose2D Planar(const Pose& p) { return {p.position.x, p.position.y, Yaw(p.orientation)}; }

}  // namespace

std::string StaticTransforms::Add(const TFMessage& message) {
  std::string refused;
  for (const TransformStamped& t : message.transforms) {
    const std::string& parent = t.header.frame_id;
    const std::string& child = t.child_frame_id;
    std::string why;
    if (parent.empty() || child.empty() || parent == child) {
      why = "frames '" + parent + "' → '" + child + "'";
    } else if (!Finite(t.transform)) {
      why = parent + " → " + child + ": not finite";
    } else {
      // A loop: the new parent already hangs below the child.
      std::string up = parent;
      for (int steps = 0; steps < 1000 && !why.size(); ++steps) {
        if (up == child) why = parent + " → " + child + ": closes a loop";
        auto it = parent_.find(up);
        if (it == parent_.end()) break;
        up = it->second.first;
      }
      auto it = parent_.find(child);
      if (why.empty() && it != parent_.end() && it->second.first != parent) {
        why = child + " has two parents (" + it->second.first + " and " + parent + ")";
      }
    }
    if (!why.empty()) {
      refused += (refused.empty() ? "" : "; ") + why;
      continue;
    }
    Transform tf = t.transform;
    tf.rotation = Normalised(tf.rotation);
    parent_[child] = {parent, tf};
  }
  return refused;
}

std::optional<Transform> StaticTransforms::Lookup(const std::string& base, const std::string& frame) const {
  // Both frames' chains up to their root; they meet at the first common ancestor.
  auto chain = [this](const std::string& from) {
    std::vector<std::pair<std::string, Transform>> c{{from, Transform{}}};  // frame, its pose in the root side
    std::string f = from;
    for (size_t steps = 0; steps <= parent_.size(); ++steps) {
      auto it = parent_.find(f);
      if (it == parent_.end()) break;
      c.push_back({it->second.first, Compose(it->second.second, c.back().second)});
      f = it->second.first;
    }
    return c;
  };
  const auto a = chain(frame), b = chain(base);
  for (const auto& [fa, pose_in_fa] : a) {
    for (const auto& [fb, base_in_fb] : b) {
      if (fa != fb) continue;
      return Compose(Inverse(base_in_fb), pose_in_fa);  // frame and base both in fa (= fb)
    }
  }
  return std::nullopt;
}

std::optional<Pose2D> MessageDecoder::Mount(const std::string& frame, bool* mirrored) {
  if (auto it = mounts_.find(frame); it != mounts_.end()) {
    *mirrored = it->second.mirrored;
    return it->second.pose;
  }
  const std::string base =
      !robot_frame_.empty() ? robot_frame_ : (!odom_child_frame_.empty() ? odom_child_frame_ : "base_footprint");
  if (frame == base) return Pose2D{};
  const std::optional<Transform> t = tf_static_.Lookup(base, frame);
  if (!t) return std::nullopt;
  // The scan plane's axes in the robot's frame: yaw from the x axis; a z axis pointing down (a lidar
  // mounted upside down) mirrors the beams' angles.
  const Vector3 x = Rotate(t->rotation, {1, 0, 0}), z = Rotate(t->rotation, {0, 0, 1});
  MountCache c{{t->translation.x, t->translation.y, std::atan2(x.y, x.x)}, z.z < 0};
  mounts_[frame] = c;
  *mirrored = c.mirrored;
  return c.pose;
}

bool MessageDecoder::LidarEvent(const LaserScan& s, const std::string& topic, Event* ev) {
  const size_t n = s.ranges.size();
  if (n == 0) return false;
  if (!std::isfinite(s.angle_min) || !std::isfinite(s.angle_max) || !std::isfinite(s.angle_increment) ||
      s.angle_increment == 0.0f) {
    throw std::runtime_error("angle_min, angle_max or angle_increment is not a finite, non-zero angle");
  }
  const double span = (double(s.angle_max) - double(s.angle_min)) / double(s.angle_increment);
  if (!(span > -1.0 && span < 1e6) || std::abs(std::llround(span) + 1 - static_cast<long long>(n)) > 1) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "angle fields (min %.4f, max %.4f, increment %.6f rad: %.0f beams) disagree with its %zu ranges",
                  s.angle_min, s.angle_max, s.angle_increment, span + 1.0, n);
    throw std::runtime_error(text);
  }
  if (!s.intensities.empty() && s.intensities.size() != n) {
    throw std::runtime_error(std::to_string(s.intensities.size()) + " intensities for " + std::to_string(n) +
                             " ranges");
  }
  bool mirrored = false;
  std::optional<Pose2D> mount = Mount(s.header.frame_id, &mirrored);
  if (!mount) {
    // Live, /tf_static comes once discovery has matched its latched writer: scans before it are
    // held back (dropped, counted) for a while rather than put in the map with a wrong mount.
    if (first_unmounted_us_ == 0) first_unmounted_us_ = ev->t_us;
    if (ev->t_us - first_unmounted_us_ < wait_for_mount_us_) {
      ++scans_waiting_for_mount_;
      return false;
    }
    if (warned_.insert("mount:" + s.header.frame_id).second) {
      mbot::log::Warn(where_ + ": " + topic + ": no transform from the robot's frame to the scan's frame '" +
                      s.header.frame_id +
                      "' in /tf_static (yet): until there is one, the lidar is taken to sit at "
                      "the robot's centre, facing forward");
    }
    mount = Pose2D{};
  }
  msgs::LidarScan scan;
  scan.ranges_m.resize(n);
  scan.angles_rad.resize(n);
  const float lo = std::max(0.0f, std::isfinite(s.range_min) ? s.range_min : 0.0f);
  const float hi = std::isfinite(s.range_max) && s.range_max > 0 ? s.range_max : INFINITY;
  for (size_t i = 0; i < n; ++i) {
    const float r = s.ranges[i];
    // REP 117: NaN, ±inf and what lies outside [range_min, range_max] are no return.
    scan.ranges_m[i] = std::isfinite(r) && r >= lo && r <= hi ? r : 0.0f;
    const float a = s.angle_min + float(i) * s.angle_increment;
    scan.angles_rad[i] = mirrored ? -a : a;
  }
  const int64_t stamp = StampUs(s.header.stamp);
  if (s.time_increment > 0 && std::isfinite(s.time_increment) && s.time_increment * n < 10.0f) {
    scan.beam_times_us.resize(n);
    for (size_t i = 0; i < n; ++i) scan.beam_times_us[i] = stamp + std::llround(double(i) * s.time_increment * 1e6);
  }
  scan.intensities = s.intensities;
  scan.max_range_m = std::isfinite(hi) ? hi : 0.0f;
  scan.sensor_pose = *mount;
  ev->kind = EventKind::kLidar;
  ev->stamp_us = stamp;
  ev->payload = std::move(scan);
  return true;
}

MessageDecoder::Type MessageDecoder::TypeOf(const std::string& type, const std::string& wire) {
  const std::pair<const char*, Type> types[] = {{kLaserScanType, Type::kScan},
                                                {kOdometryType, Type::kOdometry},
                                                {kImuType, Type::kImu},
                                                {kTwistType, Type::kTwist},
                                                {kPoseStampedType, Type::kPoseStamped},
                                                {kPoseWithCovarianceStampedType, Type::kPoseWithCovariance},
                                                {kEncodersType, Type::kEncoders},
                                                {kMotorVelocityType, Type::kMotorVelocity},
                                                {kOccupancyGridType, Type::kMap},
                                                {kStringType, Type::kString}};
  if (type == kTFMessageType) return wire == "/tf_static" ? Type::kTfStatic : Type::kTf;
  for (const auto& [name, t] : types) {
    if (type == name) return t;
  }
  return Type::kUnknown;
}

std::vector<std::pair<std::string, std::string>> MessageDecoder::Details() const {
  std::vector<std::pair<std::string, std::string>> d;
  for (const auto& [frame, m] : mounts_) {
    char text[160];
    std::snprintf(text, sizeof text, "x %.3f m, y %.3f m, yaw %.1f deg%s (from /tf_static)", m.pose.x, m.pose.y,
                  m.pose.theta * 180.0 / M_PI, m.mirrored ? ", mounted upside down" : "");
    d.push_back({"lidar " + frame, text});
  }
  if (scans_waiting_for_mount_ > 0)
    d.push_back({"scans dropped waiting for /tf_static", std::to_string(scans_waiting_for_mount_)});
  return d;
}

bool MessageDecoder::Decode(Type type, const std::string& topic, const std::string& wire, const uint8_t* d, size_t size,
                            Serialization s, int64_t t_us, const msgs::ChannelRoles& roles, Event* ev,
                            std::string* refused) {
  switch (type) {
    case Type::kUnknown:
    case Type::kTf:  // the odometry's, which /odom carries
      return false;
    case Type::kScan: return LidarEvent(DecodeLaserScan(d, size, s), wire, ev);
    case Type::kOdometry: {
      const Odometry o = DecodeOdometry(d, size, s);
      if (odom_child_frame_.empty() && !o.child_frame_id.empty()) odom_child_frame_ = o.child_frame_id;
      ev->kind = EventKind::kOdometry;
      ev->stamp_us = StampUs(o.header.stamp);
      ev->payload = Planar(o.pose);
      return true;
    }
    case Type::kImu: {
      const Imu i = DecodeImu(d, size, s);
      msgs::Imu imu;
      imu.gyro_rad_s[0] = i.angular_velocity.x, imu.gyro_rad_s[1] = i.angular_velocity.y;
      imu.gyro_rad_s[2] = i.angular_velocity.z;
      imu.accel_m_s2[0] = i.linear_acceleration.x, imu.accel_m_s2[1] = i.linear_acceleration.y;
      imu.accel_m_s2[2] = i.linear_acceleration.z;
      // orientation_covariance[0] = -1: no orientation estimate (sensor_msgs/Imu).
      if (i.orientation_covariance[0] != -1.0) {
        const Quaternion& q = i.orientation;
        imu.angles_rpy_rad[0] = std::atan2(2 * (q.w * q.x + q.y * q.z), 1 - 2 * (q.x * q.x + q.y * q.y));
        imu.angles_rpy_rad[1] = std::asin(std::clamp(2 * (q.w * q.y - q.z * q.x), -1.0, 1.0));
        imu.angles_rpy_rad[2] = Yaw(q);
        imu.has_angles = true;
      }
      ev->kind = EventKind::kImu;
      ev->stamp_us = StampUs(i.header.stamp);
      ev->payload = imu;
      return true;
    }
    case Type::kTwist: {
      const Twist t = DecodeTwist(d, size, s);
      if (!std::isfinite(t.linear.x) || !std::isfinite(t.angular.z)) throw std::runtime_error("velocity not finite");
      ev->kind = EventKind::kMotorCommand;
      ev->stamp_us = t_us;
      ev->payload = msgs::MotorCommand::Velocity(t.linear.x, t.angular.z);
      return true;
    }
    case Type::kTfStatic: {
      *refused = tf_static_.Add(DecodeTFMessage(d, size, s));
      mounts_.clear();
      return false;
    }
    case Type::kEncoders: {
      const Encoders e = DecodeEncoders(d, size, s);
      ev->kind = EventKind::kEncoders;
      ev->stamp_us = StampUs(e.stamp) != 0 ? StampUs(e.stamp) : t_us;
      ev->payload = msgs::EncoderTicks{e.ticks[0], e.ticks[1], e.delta_ticks[0], e.delta_ticks[1], e.delta_time};
      return true;
    }
    case Type::kMotorVelocity: {  // no stamp: the time it came
      const MotorVelocity m = DecodeMotorVelocity(d, size, s);
      if (!std::isfinite(m.velocity[0]) || !std::isfinite(m.velocity[1]))
        throw std::runtime_error("non-finite velocity");
      ev->kind = EventKind::kWheelSpeed;
      ev->stamp_us = t_us;
      ev->payload = msgs::WheelSpeeds{m.velocity[0], m.velocity[1]};
      return true;
    }
    case Type::kMap: {
      const OccupancyGrid g = DecodeOccupancyGrid(d, size, s);
      if (!(g.info.resolution > 0) || !std::isfinite(g.info.resolution) || g.info.width > 100000 ||
          g.info.height > 100000) {
        throw std::runtime_error("map of " + std::to_string(g.info.width) + " x " + std::to_string(g.info.height) +
                                 " cells of " + std::to_string(g.info.resolution) + " m");
      }
      auto grid =
          std::make_shared<msgs::OccupancyGrid>(static_cast<int>(g.info.width), static_cast<int>(g.info.height),
                                                g.info.resolution, g.info.origin.position.x, g.info.origin.position.y);
      // The map_server's trinary values back to log-odds: occupied +, free −, unknown 0.
      std::vector<int8_t>& cells = grid->cells();
      for (size_t i = 0; i < cells.size(); ++i) {
        const int8_t v = g.data[i];
        cells[i] = v < 0 ? 0 : (v >= 50 ? 100 : -100);
      }
      ev->kind = EventKind::kMap;
      ev->stamp_us = StampUs(g.header.stamp);
      ev->payload = std::shared_ptr<const msgs::OccupancyGrid>(std::move(grid));
      return true;
    }
    case Type::kString: {
      const std::optional<msgs::MissionStatus> m = ParseMissionState(DecodeString(d, size, s).data);
      if (!m) return false;
      ev->kind = EventKind::kMissionStatus;
      ev->stamp_us = t_us;
      ev->payload = *m;
      return true;
    }
    case Type::kPoseStamped:
    case Type::kPoseWithCovariance: {  // the pose role of the topic
      Pose2D pose;
      if (type == Type::kPoseStamped) {
        const PoseStamped p = DecodePoseStamped(d, size, s);
        pose = Planar(p.pose), ev->stamp_us = StampUs(p.header.stamp);
      } else {
        const PoseWithCovarianceStamped p = DecodePoseWithCovarianceStamped(d, size, s);
        pose = Planar(p.pose), ev->stamp_us = StampUs(p.header.stamp);
      }
      auto has = [&](const std::vector<std::string>& names) {
        return std::find(names.begin(), names.end(), topic) != names.end();
      };
      if (has(roles.ground_truth)) {
        ev->kind = EventKind::kGroundTruth;
      } else if (has(roles.reference_pose)) {
        ev->kind = EventKind::kReferencePose;
      } else if (has(roles.pose_estimate)) {
        ev->kind = EventKind::kPoseEstimate;
      } else {
        ev->kind = EventKind::kOther;
      }
      ev->payload = pose;
      return true;
    }
  }
  return false;
}

}  // namespace mbot::ros2
