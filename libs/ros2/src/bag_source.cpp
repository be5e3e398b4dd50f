#include "bag_source.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

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

bool HasMagic(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  char head[8] = {};
  in.read(head, 8);
  return in.gcount() == 8 && std::string(head, 8) == std::string("\x89MCAP0\r\n", 8);
}

// rosbag2's metadata.yaml lists its files under relative_file_paths ("  - name_0.mcap").
std::vector<std::string> MetadataFiles(const std::filesystem::path& folder) {
  std::ifstream in(folder / "metadata.yaml");
  std::vector<std::string> files;
  std::string line;
  bool in_list = false;
  while (std::getline(in, line)) {
    const size_t start = line.find_first_not_of(' ');
    if (start == std::string::npos) continue;
    if (line.compare(start, 20, "relative_file_paths:") == 0) {
      in_list = true;
      continue;
    }
    if (!in_list) continue;
    if (line.compare(start, 2, "- ") != 0) break;
    std::string name = line.substr(start + 2);
    while (!name.empty() && (name.back() == ' ' || name.back() == '\r')) name.pop_back();
    if (name.size() >= 2 && (name.front() == '\'' || name.front() == '"')) name = name.substr(1, name.size() - 2);
    files.push_back((folder / name).string());
  }
  return files;
}

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

namespace {

class McapFile : public BagFile {
 public:
  explicit McapFile(const std::string& path) : r_(path) {}
  bool Next(McapMessage* m) override { return r_.Next(m); }
  std::optional<ChannelDesc> Channel(uint16_t id) const override {
    const auto ch = r_.channels().find(id);
    if (ch == r_.channels().end()) return std::nullopt;
    const auto schema = r_.schemas().find(ch->second.schema_id);
    return ChannelDesc{ch->second.topic, schema != r_.schemas().end() ? schema->second.name : "",
                       ch->second.message_encoding};
  }
  uint64_t position() const override { return r_.position(); }
  long long messages() const override { return r_.stats().messages; }
  long long chunks() const override { return r_.stats().chunks; }
  long long crcs() const override { return r_.stats().crcs_checked; }
  bool truncated() const override { return r_.stats().truncated; }

 private:
  McapReader r_;
};

class Ros1File : public BagFile {
 public:
  explicit Ros1File(const std::string& path) : r_(path) {}
  bool Next(McapMessage* m) override { return r_.Next(m); }
  std::optional<ChannelDesc> Channel(uint16_t id) const override {
    const auto c = r_.connections().find(id);
    if (c == r_.connections().end()) return std::nullopt;
    // ROS 1 names types "pkg/Type"; the decoders know them by ROS 2's "pkg/msg/Type".
    std::string type = c->second.type;
    if (const size_t slash = type.find('/'); slash != std::string::npos && type.find("/msg/") == std::string::npos) {
      type = type.substr(0, slash) + "/msg/" + type.substr(slash + 1);
    }
    return ChannelDesc{c->second.topic, type, "ros1"};
  }
  uint64_t position() const override { return r_.position(); }
  long long messages() const override { return r_.messages(); }
  long long chunks() const override { return r_.chunks(); }
  long long crcs() const override { return 0; }  // ROS 1 bags have none
  bool truncated() const override { return r_.truncated(); }

 private:
  Ros1BagReader r_;
};

bool HasRos1Magic(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  char head[13] = {};
  in.read(head, 13);
  return in.gcount() == 13 && std::string(head, 13) == "#ROSBAG V2.0\n";
}

}  // namespace

std::unique_ptr<BagFile> OpenBagFile(const std::string& path) {
  if (HasRos1Magic(path)) return std::make_unique<Ros1File>(path);
  return std::make_unique<McapFile>(path);
}

std::vector<std::string> BagFiles(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(path, ec)) return {path};  // a .mcap or a ROS 1 .bag
  std::vector<std::string> files = MetadataFiles(path);
  if (files.empty()) {
    for (const auto& entry : fs::directory_iterator(path, ec)) {
      if (entry.path().extension() == ".mcap") files.push_back(entry.path().string());
    }
    std::sort(files.begin(), files.end());
  }
  if (files.empty())
    throw std::runtime_error(path + ": a folder with no .mcap file (not a rosbag2 bag with storage mcap)");
  for (const std::string& f : files) {
    if (!fs::is_regular_file(f, ec))
      throw std::runtime_error(path + ": metadata.yaml lists " + f + ", which is missing");
    if (!HasMagic(f)) throw std::runtime_error(f + ": not an MCAP file (no MCAP magic bytes)");
  }
  return files;
}

McapBagSource::McapBagSource(const msgs::SourceOptions& options)
    : options_(options), bag_(msgs::ExtraOr<BagSourceOptions>(options)), files_(BagFiles(options.path)) {
  std::error_code ec;
  for (const std::string& f : files_) bytes_total_ += std::filesystem::file_size(f, ec);
  ros1_ = HasRos1Magic(files_[0]);
  reader_ = OpenBagFile(files_[0]);
}

double McapBagSource::Progress() const {
  if (eof_ || bytes_total_ == 0) return 1.0;
  return std::min(1.0, double(bytes_before_ + (reader_ ? reader_->position() : 0)) / double(bytes_total_));
}

std::vector<std::pair<std::string, std::string>> McapBagSource::Details() const {
  std::vector<std::pair<std::string, std::string>> d = {
      {"files", std::to_string(files_.size())},
      {"messages", std::to_string(messages_ + (reader_ ? reader_->messages() : 0))},
      {"chunks", std::to_string(chunks_ + (reader_ ? reader_->chunks() : 0))},
      {"CRCs checked", std::to_string(crcs_ + (reader_ ? reader_->crcs() : 0))}};
  for (const auto& [frame, m] : mounts_) {
    char text[160];
    std::snprintf(text, sizeof text, "x %.3f m, y %.3f m, yaw %.1f deg%s (from /tf_static)", m.pose.x, m.pose.y,
                  m.pose.theta * 180.0 / M_PI, m.mirrored ? ", mounted upside down" : "");
    d.push_back({"lidar " + frame, text});
  }
  return d;
}

bool McapBagSource::ReadMore() {
  while (reader_) {
    McapMessage m;
    bool got = false;
    try {
      got = reader_->Next(&m);
    } catch (const std::runtime_error& e) {  // McapError, Ros1BagError
      // What came before the damage was read; the rest of this file cannot be trusted.
      mbot::log::Warn(std::string(e.what()) + " (the file's messages up to there were replayed)");
      diagnostics_.truncated_tail = true;
      got = false;
    }
    if (got) {
      Handle(m);
      return true;
    }
    if (reader_->truncated()) diagnostics_.truncated_tail = true;
    messages_ += reader_->messages();
    chunks_ += reader_->chunks();
    crcs_ += reader_->crcs();
    std::error_code ec;
    bytes_before_ += std::filesystem::file_size(files_[file_index_], ec);
    reader_.reset();
    routes_.clear();  // channel ids are per file
    if (++file_index_ < files_.size()) reader_ = OpenBagFile(files_[file_index_]);
  }
  return false;
}

void McapBagSource::Reject(const std::string& topic, const McapMessage& m, const std::string& why) {
  ++diagnostics_.rejected_messages;
  mbot::log::Warn(files_[file_index_] + ": rejected message on topic " + topic + " (sequence " +
                  std::to_string(m.sequence) + ", record at byte " + std::to_string(m.offset) + "): " + why);
}

std::optional<Pose2D> McapBagSource::Mount(const std::string& frame, bool* mirrored) {
  if (auto it = mounts_.find(frame); it != mounts_.end()) {
    *mirrored = it->second.mirrored;
    return it->second.pose;
  }
  const std::string base = !bag_.robot_frame.empty()
                               ? bag_.robot_frame
                               : (!odom_child_frame_.empty() ? odom_child_frame_ : "base_footprint");
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

bool McapBagSource::LidarEvent(const LaserScan& s, const std::string& topic, Event* ev) {
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
    if (warned_.insert("mount:" + s.header.frame_id).second) {
      mbot::log::Warn(options_.path + ": " + topic + ": no transform from the robot's frame to the scan's frame '" +
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

McapBagSource::Route McapBagSource::RouteOf(uint16_t channel_id) {
  // Once per channel of each file: what its messages are, under which topic.
  Route r;
  const std::optional<BagFile::ChannelDesc> ch = reader_->Channel(channel_id);
  if (!ch) return r;  // the reader checks that a message's channel came first
  r.wire = ch->topic;
  const std::string type = ch->type;
  r.topic = bag_.topics.Topic(r.wire);
  msgs::ChannelInfo& info = channels_[r.topic];  // keyed by the pipeline's topic, as the events are
  info.type = type;
  info.generation = std::string(ch->encoding == "ros1" ? "ROS 1 " : "ROS 2 ") + r.wire + " (" + ch->encoding + ")";
  r.info = &info;
  const std::pair<const char*, Route::Type> types[] = {{kLaserScanType, Route::kScan},
                                                       {kOdometryType, Route::kOdometry},
                                                       {kImuType, Route::kImu},
                                                       {kTwistType, Route::kTwist},
                                                       {kTFMessageType, Route::kTf},
                                                       {kPoseStampedType, Route::kPoseStamped},
                                                       {kPoseWithCovarianceStampedType, Route::kPoseWithCovariance}};
  for (const auto& [name, t] : types) {
    if (type == name) r.type = t;
  }
  if (ch->encoding == "ros1") r.serialization = Serialization::kRos1;
  if (ch->encoding != "cdr" && ch->encoding != "ros1") r.type = Route::kUnknown;
  if (r.type == Route::kUnknown) {
    info.decoded = false;
    mbot::log::Warn(files_[file_index_] + ": topic " + r.wire + " carries " + (type.empty() ? "no schema" : type) +
                    " (" + ch->encoding +
                    "), which this reader does not decode; its messages are "
                    "skipped");
  }
  if (r.type == Route::kTf) info.kind = EventKind::kOther;
  r.type_name = type;
  return r;
}

void McapBagSource::Handle(const McapMessage& m) {
  auto found = routes_.find(m.channel_id);
  if (found == routes_.end()) found = routes_.emplace(m.channel_id, RouteOf(m.channel_id)).first;
  const Route& route = found->second;
  if (!route.info) return;
  if (route.type == Route::kUnknown) {
    ++diagnostics_.unknown_messages;
    return;
  }
  if (route.type == Route::kTf && route.wire != "/tf_static") return;  // the odometry's, which /odom carries
  const std::string& wire = route.wire;
  const std::string& topic = route.topic;
  const std::string& type = route.type_name;
  msgs::ChannelInfo& info = *route.info;
  const int64_t t_us = static_cast<int64_t>(m.log_time_ns / 1000);
  if (!msgs::IsPlausibleTimeUs(t_us)) {
    Reject(wire, m, "absurd log time " + std::to_string(m.log_time_ns) + " ns");
    return;
  }
  Event ev;
  ev.t_us = t_us;
  ev.channel = topic;
  const uint8_t* d = m.data.data();
  const size_t size = m.data.size();
  try {
    if (route.type == Route::kScan) {
      if (!LidarEvent(DecodeLaserScan(d, size, route.serialization), wire, &ev)) return;
    } else if (route.type == Route::kOdometry) {
      const Odometry o = DecodeOdometry(d, size, route.serialization);
      if (odom_child_frame_.empty() && !o.child_frame_id.empty()) odom_child_frame_ = o.child_frame_id;
      ev.kind = EventKind::kOdometry;
      ev.stamp_us = StampUs(o.header.stamp);
      ev.payload = Planar(o.pose);
    } else if (route.type == Route::kImu) {
      const Imu i = DecodeImu(d, size, route.serialization);
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
      ev.kind = EventKind::kImu;
      ev.stamp_us = StampUs(i.header.stamp);
      ev.payload = imu;
    } else if (route.type == Route::kTwist) {
      const Twist t = DecodeTwist(d, size, route.serialization);
      ev.kind = EventKind::kMotorCommand;
      ev.stamp_us = t_us;
      ev.payload = msgs::MotorCommand::Velocity(t.linear.x, t.angular.z);
    } else if (route.type == Route::kTf) {  // /tf_static
      const std::string refused = tf_static_.Add(DecodeTFMessage(d, size, route.serialization));
      mounts_.clear();
      if (!refused.empty()) {
        ++diagnostics_.rejected_messages;
        mbot::log::Warn(files_[file_index_] + ": topic " + wire + " (record at byte " + std::to_string(m.offset) +
                        "): transforms refused: " + refused);
      }
      return;
    } else {  // PoseStamped, PoseWithCovarianceStamped: the pose role of the topic
      Pose2D pose;
      if (route.type == Route::kPoseStamped) {
        const PoseStamped p = DecodePoseStamped(d, size, route.serialization);
        pose = Planar(p.pose), ev.stamp_us = StampUs(p.header.stamp);
      } else {
        const PoseWithCovarianceStamped p = DecodePoseWithCovarianceStamped(d, size, route.serialization);
        pose = Planar(p.pose), ev.stamp_us = StampUs(p.header.stamp);
      }
      const msgs::ChannelRoles& roles = options_.roles;
      auto has = [&](const std::vector<std::string>& names) {
        return std::find(names.begin(), names.end(), topic) != names.end();
      };
      if (has(roles.ground_truth)) {
        ev.kind = EventKind::kGroundTruth;
      } else if (has(roles.reference_pose)) {
        ev.kind = EventKind::kReferencePose;
      } else if (has(roles.pose_estimate)) {
        ev.kind = EventKind::kPoseEstimate;
      } else {
        ev.kind = EventKind::kOther;
      }
      ev.payload = pose;
    }
  } catch (const std::exception& e) {  // CdrError names the field and offset
    Reject(wire, m, std::string(type) + ": " + e.what());
    return;
  }
  info.kind = ev.kind;
  if (ev.kind == EventKind::kOther) return;
  if (t_us < last_emitted_us_) {
    ++diagnostics_.out_of_order;
    if (warned_.insert("order:" + wire).second) {
      mbot::log::Warn(files_[file_index_] + ": topic " + wire + ": a message " +
                      std::to_string((last_emitted_us_ - t_us) * 1e-3) +
                      " ms older than one already replayed "
                      "(beyond reorder_window_s) is skipped; such messages are counted");
    }
    return;
  }
  pending_.emplace(t_us, std::move(ev));
}

std::optional<Event> McapBagSource::Next() {
  while (true) {
    if (!pending_.empty() && (eof_ || pending_.rbegin()->first - pending_.begin()->first > bag_.reorder_window_us)) {
      Event ev = std::move(pending_.begin()->second);
      pending_.erase(pending_.begin());
      last_emitted_us_ = ev.t_us;
      return ev;
    }
    if (eof_) return std::nullopt;
    if (!ReadMore()) eof_ = true;
  }
}

}  // namespace mbot::ros2
