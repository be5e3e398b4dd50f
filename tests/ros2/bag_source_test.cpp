// The mcap source on bags written here with McapWriter: what it makes of each message type, and bad
// input — angle fields that disagree with the ranges, a /tf loop, an unknown schema, a CDR length
// past the buffer, a file cut short — each a counted warning naming the topic, never a crash.
// (Bags of writers we did not write: tests/ros2/bag_replay_test.py, recorder_interop.py.)
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "mbot/msgs/source.hpp"
#include "mbot/ros2/definitions.hpp"
#include "mbot/ros2/mcap_reader.hpp"
#include "mbot/ros2/mcap_writer.hpp"
#include "mbot/ros2/messages.hpp"
#include "mbot/ros2/ros2_transport.hpp"

namespace mbot::ros2 {
namespace {

std::string TempPath(const std::string& name) { return ::testing::TempDir() + "/" + name; }

class Bag {
 public:
  explicit Bag(const std::string& path) : w_(path) {}
  uint16_t Topic(const std::string& topic, const std::string& type) {
    return w_.AddChannel(w_.AddSchema(type, "ros2msg", type.find("mbot") == 0 ? "int32 x\n" : Definition(type)), topic,
                         "cdr", {{"offered_qos_profiles", ""}});
  }
  void Put(uint16_t ch, double t_s, const std::vector<uint8_t>& data) {
    w_.Write(ch, uint64_t(t_s * 1e9), uint64_t(t_s * 1e9), data);
  }
  void Close() { w_.Close(); }

 private:
  McapWriter w_;
};

LaserScan Scan(double t_s, size_t n) {
  LaserScan s;
  s.header.stamp.sec = int32_t(t_s);
  s.header.stamp.nanosec = uint32_t((t_s - int32_t(t_s)) * 1e9);
  s.header.frame_id = "lidar_link";
  s.angle_min = -float(M_PI);
  s.angle_increment = float(2 * M_PI / n);
  s.angle_max = s.angle_min + s.angle_increment * float(n - 1);
  s.time_increment = 0.1f / float(n);
  s.range_min = 0.15f;
  s.range_max = 12.0f;
  s.ranges.assign(n, 2.0f);
  s.ranges[0] = NAN;
  s.ranges[1] = INFINITY;
  s.ranges[2] = 0.05f;  // below range_min
  return s;
}

TFMessage Mount() {
  TFMessage tf;
  TransformStamped a, b;
  a.header.frame_id = "base_footprint", a.child_frame_id = "base_link", a.transform.translation.z = 0.042;
  b.header.frame_id = "base_link", b.child_frame_id = "lidar_link", b.transform.translation = {0.03, 0.0, 0.142};
  b.transform.rotation = FromYaw(M_PI);
  tf.transforms = {a, b};
  return tf;
}

std::vector<msgs::Event> ReadAll(const std::string& path, msgs::SourceDiagnostics* diagnostics = nullptr) {
  RegisterRos2Transport();
  msgs::SourceOptions o;
  o.type = "auto";
  o.path = path;
  std::unique_ptr<msgs::Source> source = msgs::OpenSource(o);
  std::vector<msgs::Event> events;
  while (auto e = source->Next()) events.push_back(*e);
  if (diagnostics) *diagnostics = source->diagnostics();
  return events;
}

TEST(McapBagSource, MessagesBecomeEventsWithTheLidarMountFromTfStatic) {
  const std::string path = TempPath("good.mcap");
  {
    Bag bag(path);
    const uint16_t tf = bag.Topic("/tf_static", kTFMessageType), scan = bag.Topic("/scan", kLaserScanType),
                   odom = bag.Topic("/odom", kOdometryType), cmd = bag.Topic("/cmd_vel", kTwistType);
    bag.Put(tf, 10.0, Encode(Mount()));
    Odometry o;
    o.child_frame_id = "base_footprint";
    o.pose.position = {1.0, 2.0, 0.0};
    o.pose.orientation = FromYaw(0.5);
    bag.Put(odom, 10.01, Encode(o));
    bag.Put(scan, 10.1, Encode(Scan(10.0, 360)));
    bag.Put(cmd, 10.2, Encode(Twist{{0.25, 0, 0}, {0, 0, -0.5}}));
    bag.Close();
  }
  ASSERT_EQ(msgs::DetectFormat(path), "mcap");
  const auto events = ReadAll(path);
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(events[0].kind, msgs::EventKind::kOdometry);
  EXPECT_EQ(events[0].channel, msgs::topics::kOdometry);
  EXPECT_NEAR(std::get<msgs::Pose2D>(events[0].payload).theta, 0.5, 1e-12);
  ASSERT_EQ(events[1].kind, msgs::EventKind::kLidar);
  EXPECT_EQ(events[1].channel, msgs::topics::kLidar);
  EXPECT_EQ(events[1].t_us, 10'100'000);
  const auto& s = std::get<msgs::LidarScan>(events[1].payload);
  ASSERT_EQ(s.ranges_m.size(), 360u);
  EXPECT_EQ(s.ranges_m[0], 0.0f);  // NaN, inf and below range_min: no return
  EXPECT_EQ(s.ranges_m[1], 0.0f);
  EXPECT_EQ(s.ranges_m[2], 0.0f);
  EXPECT_EQ(s.ranges_m[3], 2.0f);
  EXPECT_NEAR(s.sensor_pose.x, 0.03, 1e-9);
  EXPECT_NEAR(std::abs(s.sensor_pose.theta), M_PI, 1e-9);
  ASSERT_EQ(s.beam_times_us.size(), 360u);
  EXPECT_NEAR(double(s.beam_times_us.back() - s.beam_times_us.front()), 0.1e6 * 359 / 360, 2.0);
  EXPECT_EQ(events[2].kind, msgs::EventKind::kMotorCommand);
  EXPECT_EQ(std::get<msgs::MotorCommand>(events[2].payload).velocity.w_rad_s, -0.5);
}

TEST(McapBagSource, BadMessagesAreCountedAndNamedNeverACrash) {
  const std::string path = TempPath("bad.mcap");
  {
    Bag bag(path);
    const uint16_t tf = bag.Topic("/tf_static", kTFMessageType), scan = bag.Topic("/scan", kLaserScanType),
                   odom = bag.Topic("/odom", kOdometryType), enc = bag.Topic("/encoders", "mbot_interfaces/msg/X");
    TFMessage loop = Mount();
    loop.transforms.push_back(loop.transforms[0]);
    loop.transforms.back().header.frame_id = "lidar_link", loop.transforms.back().child_frame_id = "base_footprint";
    bag.Put(tf, 1.0, Encode(loop));  // the third transform closes a loop: refused, the others kept
    LaserScan wrong = Scan(1.0, 360);
    wrong.ranges.resize(200);  // the angle fields say 360
    bag.Put(scan, 1.1, Encode(wrong));
    std::vector<uint8_t> cut = Encode(Scan(1.2, 360));
    cut.resize(cut.size() / 2);  // the ranges' count runs past the buffer
    bag.Put(scan, 1.2, cut);
    std::vector<uint8_t> huge = Encode(Odometry{});
    huge[4 + 8] = 0xff, huge[4 + 9] = 0xff, huge[4 + 10] = 0xff, huge[4 + 11] = 0x7f;  // frame_id length 2 GB
    bag.Put(odom, 1.3, huge);
    bag.Put(enc, 1.4, {0, 1, 0, 0, 1, 2, 3, 4});
    bag.Put(scan, 1.5, Encode(Scan(1.5, 360)));
    bag.Close();
  }
  msgs::SourceDiagnostics d;
  const auto events = ReadAll(path, &d);
  ASSERT_EQ(events.size(), 1u);  // the one good scan
  EXPECT_NEAR(std::abs(std::get<msgs::LidarScan>(events[0].payload).sensor_pose.theta), M_PI, 1e-9);
  EXPECT_EQ(d.rejected_messages, 4);  // the loop, the angles, the cut ranges, the huge string
  EXPECT_EQ(d.unknown_messages, 1);
}

TEST(McapBagSource, AFileCutShortGivesWhatCameBeforeTheCut) {
  const std::string path = TempPath("whole.mcap"), cut = TempPath("cut.mcap");
  {
    McapWriterOptions o;
    o.chunk_size = 4096;  // many chunks
    McapWriter w(path, o);
    const uint16_t ch = w.AddChannel(w.AddSchema(kTwistType, "ros2msg", Definition(kTwistType)), "/cmd_vel", "cdr", {});
    for (int i = 0; i < 2000; ++i) w.Write(ch, uint64_t(i) * 10'000'000, 0, Encode(Twist{{i * 1e-3, 0, 0}, {}}));
    w.Close();
  }
  const auto size = std::filesystem::file_size(path);
  {
    std::ifstream in(path, std::ios::binary);
    std::vector<char> head(size / 2);
    in.read(head.data(), std::streamsize(head.size()));
    std::ofstream(cut, std::ios::binary).write(head.data(), std::streamsize(head.size()));
  }
  msgs::SourceDiagnostics d;
  EXPECT_EQ(ReadAll(path, &d).size(), 2000u);
  EXPECT_FALSE(d.truncated_tail);
  const auto events = ReadAll(cut, &d);
  EXPECT_GT(events.size(), 500u);
  EXPECT_LT(events.size(), 2000u);
  EXPECT_TRUE(d.truncated_tail);
  // A flipped bit in a message (uncompressed chunks, so the message's bytes can be found): its
  // chunk's CRC fails, and what came before that chunk is kept.
  const std::string plain = TempPath("plain.mcap");
  {
    McapWriterOptions o;
    o.chunk_size = 4096;
    o.compression = "";
    McapWriter w(plain, o);
    const uint16_t ch = w.AddChannel(w.AddSchema(kTwistType, "ros2msg", Definition(kTwistType)), "/cmd_vel", "cdr", {});
    for (int i = 0; i < 2000; ++i) w.Write(ch, uint64_t(i) * 10'000'000, 0, Encode(Twist{{i * 0.25, 0, 0}, {}}));
    w.Close();
  }
  std::string bytes;
  {
    std::ifstream in(plain, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  const double x = 1000 * 0.25;  // message 1000's linear.x
  const size_t at = bytes.find(std::string(reinterpret_cast<const char*>(&x), 8));
  ASSERT_NE(at, std::string::npos);
  bytes[at + 7] = char(bytes[at + 7] ^ 0x01);
  std::ofstream(plain, std::ios::binary | std::ios::trunc).write(bytes.data(), std::streamsize(bytes.size()));
  const auto flipped = ReadAll(plain, &d);
  EXPECT_GT(flipped.size(), 900u);
  EXPECT_LT(flipped.size(), 1001u);
  EXPECT_TRUE(d.truncated_tail);
}

TEST(McapWriter, WritesWhatTheReaderChecks) {
  const std::string path = TempPath("checked.mcap");
  std::filesystem::remove(path);
  {
    McapWriter w(path);
    const uint16_t ch = w.AddChannel(w.AddSchema(kTwistType, "ros2msg", Definition(kTwistType)), "/cmd_vel", "cdr",
                                     {{"offered_qos_profiles", "- depth: 10"}});
    w.Write(ch, 5, 5, Encode(Twist{}));
    w.AddMetadata("rosbag2", {{"serialized_metadata", "version: 9"}});
    EXPECT_FALSE(std::filesystem::exists(path));  // only the temporary file until closed
    w.Close();
  }
  McapReader r(path);
  McapMessage m;
  int n = 0;
  while (r.Next(&m)) ++n;
  EXPECT_EQ(n, 1);
  EXPECT_EQ(r.profile(), "ros2");
  EXPECT_TRUE(r.stats().footer);
  EXPECT_GE(r.stats().crcs_checked, 2);  // the chunk's and the data section's
  EXPECT_EQ(r.channels().at(1).metadata.at("offered_qos_profiles"), "- depth: 10");
  // A writer destroyed unclosed leaves nothing behind.
  { McapWriter w(TempPath("abandoned.mcap")); }
  EXPECT_FALSE(std::filesystem::exists(TempPath("abandoned.mcap")));
  EXPECT_FALSE(std::filesystem::exists(TempPath("abandoned.mcap.tmp")));
}

TEST(Definitions, EveryRecordedTypeIsDefinedWithItsDependencies) {
  const std::string d = Definition(kOdometryType);
  EXPECT_EQ(d.rfind("std_msgs/Header header\n", 0), 0u);
  for (const char* dep : {"MSG: std_msgs/Header", "MSG: builtin_interfaces/Time", "MSG: geometry_msgs/Pose\n",
                          "MSG: geometry_msgs/Quaternion", "MSG: geometry_msgs/TwistWithCovariance"}) {
    EXPECT_NE(d.find(dep), std::string::npos) << dep;
  }
  EXPECT_EQ(d.find("MSG: std_msgs/Header"), d.rfind("MSG: std_msgs/Header"));  // each once
  EXPECT_THROW(Definition("sensor_msgs/msg/Image"), std::out_of_range);
  // Every type the source decodes and the recorder writes has its definition.
  for (const char* type : {kLaserScanType, kOdometryType, kImuType, kTwistType, kTFMessageType, kPoseStampedType,
                           kPoseWithCovarianceStampedType, kPoseArrayType, kPathType, kOccupancyGridType}) {
    EXPECT_NO_THROW(Definition(type)) << type;
  }
}

}  // namespace
}  // namespace mbot::ros2
