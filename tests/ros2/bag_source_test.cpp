// The mcap source on bags written here with McapWriter: what it makes of each message type, and bad
// input — angle fields that disagree with the ranges, a /tf loop, an unknown schema, a CDR length
// past the buffer, a file cut short — each a counted warning naming the topic, never a crash.
// (Bags of writers we did not write: tests/ros2/bag_replay_test.py, recorder_interop.py.)
#include <bzlib.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "mbot/msgs/source.hpp"
#include "mbot/ros2/definitions.hpp"
#include "mbot/ros2/mcap_reader.hpp"
#include "mbot/ros2/mcap_writer.hpp"
#include "mbot/ros2/messages.hpp"
#include "mbot/ros2/ros1_bag.hpp"
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

namespace mbot::ros2 {
namespace {

// A ROS 1 bag written by hand (format 2.0): records of "name=value" header fields and data.
struct Ros1Bag {
  std::string bytes = "#ROSBAG V2.0\n";
  static std::string Field(const std::string& name, const std::string& value) {
    const std::string f = name + "=" + value;
    const uint32_t n = uint32_t(f.size());
    return std::string(reinterpret_cast<const char*>(&n), 4) + f;
  }
  static std::string U32(uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); }
  static std::string Record(const std::string& header, const std::string& data) {
    return U32(uint32_t(header.size())) + header + U32(uint32_t(data.size())) + data;
  }
  static std::string Connection(uint32_t id, const std::string& topic, const std::string& type) {
    return Record(Field("op", "\x07") + Field("conn", U32(id)) + Field("topic", topic),
                  Field("topic", topic) + Field("type", type) + Field("md5sum", "0"));
  }
  static std::string Message(uint32_t conn, uint32_t sec, const std::string& data) {
    return Record(Field("op", "\x02") + Field("conn", U32(conn)) + Field("time", U32(sec) + U32(0)), data);
  }
};

// ROS 1's Twist: six packed float64; its Odometry: a Header with seq, strings without NUL.
std::string Ros1Twist(double vx, double wz) {
  std::string s(48, '\0');
  std::memcpy(&s[0], &vx, 8);
  std::memcpy(&s[40], &wz, 8);
  return s;
}

TEST(Ros1Bag, ReadsConnectionsAndMessagesInAndOutOfChunks) {
  Ros1Bag b;
  std::string chunk = Ros1Bag::Connection(0, "/cmd_vel", "geometry_msgs/Twist");
  for (uint32_t t = 1; t <= 3; ++t) chunk += Ros1Bag::Message(0, 100 + t, Ros1Twist(0.1 * t, -0.5));
  b.bytes += Ros1Bag::Record(Ros1Bag::Field("op", "\x05") + Ros1Bag::Field("compression", "none") +
                                 Ros1Bag::Field("size", Ros1Bag::U32(uint32_t(chunk.size()))),
                             chunk);
  b.bytes += Ros1Bag::Message(0, 200, Ros1Twist(1.0, 0.25));  // outside a chunk, as old bags have them
  const std::string path = TempPath("small.bag");
  std::ofstream(path, std::ios::binary).write(b.bytes.data(), std::streamsize(b.bytes.size()));
  ASSERT_EQ(msgs::DetectFormat(path), "ros1_bag");
  msgs::SourceDiagnostics d;
  const auto events = ReadAll(path, &d);
  ASSERT_EQ(events.size(), 4u);
  EXPECT_EQ(events[0].kind, msgs::EventKind::kMotorCommand);
  EXPECT_EQ(events[0].t_us, 101'000'000);
  EXPECT_NEAR(std::get<msgs::MotorCommand>(events[2].payload).velocity.v_m_s, 0.3, 1e-12);
  EXPECT_EQ(std::get<msgs::MotorCommand>(events[3].payload).velocity.w_rad_s, 0.25);
  EXPECT_FALSE(d.truncated_tail);
  // Cut inside the last record: the three before it, and the cut said.
  const std::string cut = TempPath("cut.bag");
  std::ofstream(cut, std::ios::binary).write(b.bytes.data(), std::streamsize(b.bytes.size() - 10));
  EXPECT_EQ(ReadAll(cut, &d).size(), 3u);
  EXPECT_TRUE(d.truncated_tail);
}

TEST(Ros1Bag, ALyingChunkSizeOrAnUnknownConnectionIsRefusedNamingTheOffset) {
  Ros1Bag b;
  b.bytes += Ros1Bag::Record(Ros1Bag::Field("op", "\x05") + Ros1Bag::Field("compression", "bz2") +
                                 Ros1Bag::Field("size", Ros1Bag::U32(0x7fffffff)),
                             "BZh9 not really");
  const std::string path = TempPath("lying.bag");
  std::ofstream(path, std::ios::binary).write(b.bytes.data(), std::streamsize(b.bytes.size()));
  Ros1BagReader r(path);
  McapMessage m;
  try {
    r.Next(&m);
    FAIL() << "a 2 GB chunk from 15 bytes was accepted";
  } catch (const Ros1BagError& e) {
    EXPECT_NE(std::string(e.what()).find("byte 13"), std::string::npos) << e.what();
  }
  Ros1Bag orphan;
  orphan.bytes += Ros1Bag::Message(7, 1, Ros1Twist(0, 0));
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(orphan.bytes.data(), std::streamsize(orphan.bytes.size()));
  Ros1BagReader r2(path);
  EXPECT_THROW(r2.Next(&m), Ros1BagError);
  EXPECT_THROW(Ros1BagReader(TempPath("small.mcap_missing")), Ros1BagError);
}

// bz2 holds no size of its own: a chunk claiming more than it holds (within the ratio bound) is
// refused by what it decompresses to, and one claiming less by running past its claim.
TEST(Ros1Bag, ABz2ChunkClaimingAnotherSizeIsRefused) {
  std::string chunk = Ros1Bag::Connection(0, "/cmd_vel", "geometry_msgs/Twist");
  for (uint32_t t = 0; t < 50; ++t) chunk += Ros1Bag::Message(0, t, Ros1Twist(t, 0));
  std::string packed(chunk.size() + 1024, '\0');
  unsigned int packed_size = unsigned(packed.size());
  ASSERT_EQ(BZ2_bzBuffToBuffCompress(packed.data(), &packed_size, chunk.data(), unsigned(chunk.size()), 9, 0, 0),
            BZ_OK);
  packed.resize(packed_size);
  for (const uint32_t claim : {uint32_t(chunk.size() * 20), uint32_t(chunk.size() / 2)}) {
    Ros1Bag b;
    b.bytes += Ros1Bag::Record(Ros1Bag::Field("op", "\x05") + Ros1Bag::Field("compression", "bz2") +
                                   Ros1Bag::Field("size", Ros1Bag::U32(claim)),
                               packed);
    const std::string path = TempPath("bz2_claim.bag");
    std::ofstream(path, std::ios::binary | std::ios::trunc).write(b.bytes.data(), std::streamsize(b.bytes.size()));
    Ros1BagReader r(path);
    McapMessage m;
    try {
      r.Next(&m);
      FAIL() << "a bz2 chunk of " << chunk.size() << " bytes claiming " << claim << " was accepted";
    } catch (const Ros1BagError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("bz2 chunk"), std::string::npos) << what;
      EXPECT_NE(what.find("byte 13"), std::string::npos) << what;
    }
  }
}

// Chunks hold messages as they arrived, per topic: the reader gives them in time order (ties in file
// order), and a bad chunk after good ones ends the bag only once the good ones are out.
TEST(Ros1Bag, MessagesComeInTimeOrderAcrossChunksAndBeforeABadChunk) {
  auto chunk_record = [](const std::string& chunk) {
    return Ros1Bag::Record(Ros1Bag::Field("op", "\x05") + Ros1Bag::Field("compression", "none") +
                               Ros1Bag::Field("size", Ros1Bag::U32(uint32_t(chunk.size()))),
                           chunk);
  };
  Ros1Bag b;
  std::string first = Ros1Bag::Connection(0, "/cmd_vel", "geometry_msgs/Twist");
  for (uint32_t t : {10, 12, 11, 14}) first += Ros1Bag::Message(0, t, Ros1Twist(t, 0));
  std::string second;
  for (uint32_t t : {13, 15, 14}) second += Ros1Bag::Message(0, t, Ros1Twist(t + 0.5, 0));
  b.bytes += chunk_record(first) + chunk_record(second);
  const std::string path = TempPath("unsorted.bag");
  std::ofstream(path, std::ios::binary).write(b.bytes.data(), std::streamsize(b.bytes.size()));
  Ros1BagReader r(path);
  McapMessage m;
  std::vector<double> got;
  while (r.Next(&m)) {
    double vx;
    std::memcpy(&vx, m.data.data(), 8);
    got.push_back(vx);
  }
  EXPECT_EQ(got, (std::vector<double>{10, 11, 12, 13.5, 14, 14.5, 15.5}));
  EXPECT_EQ(r.messages(), 7);

  // The second chunk claims a compression nobody knows: the first chunk's four, then the error.
  Ros1Bag bad;
  bad.bytes +=
      chunk_record(first) + Ros1Bag::Record(Ros1Bag::Field("op", "\x05") + Ros1Bag::Field("compression", "zip") +
                                                Ros1Bag::Field("size", Ros1Bag::U32(4)),
                                            "abcd");
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(bad.bytes.data(), std::streamsize(bad.bytes.size()));
  Ros1BagReader r2(path);
  int n = 0;
  try {
    while (r2.Next(&m)) ++n;
    ADD_FAILURE() << "a chunk compressed with 'zip' was read";
  } catch (const Ros1BagError& e) {
    EXPECT_NE(std::string(e.what()).find("'zip'"), std::string::npos) << e.what();
  }
  EXPECT_EQ(n, 4);
}

}  // namespace
}  // namespace mbot::ros2
