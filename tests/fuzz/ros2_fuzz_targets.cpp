// libFuzzer targets of the ROS 2 transport's parsers (libs/ros2 only, so they build in a minute):
//   mcap  a file given to the `mcap` source (McapReader, chunks, CRCs, every decoder, /tf_static);
//   cdr   the first byte picks a message type, the rest is its CDR payload;
//   ros1_bag  a file given to the `ros1_bag` source (Ros1BagReader, bz2/lz4 chunks, ROS 1 decoders).
// With MBOT_FUZZ_SEED_DIR set, LLVMFuzzerInitialize writes the seeds there first: small bags of
// every message type (zstd-compressed and plain chunks), each type's encoding, and ROS 1 bags
// (uncompressed, bz2 and lz4 chunks) of the first messages of MBOT_FUZZ_ROS1_BAG (scripts/fuzz.sh).
#include <bzlib.h>
#include <lz4frame.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "mbot/common/log.hpp"
#include "mbot/msgs/source.hpp"
#include "mbot/ros2/definitions.hpp"
#include "mbot/ros2/mcap_writer.hpp"
#include "mbot/ros2/messages.hpp"
#include "mbot/ros2/ros1_bag.hpp"
#include "mbot/ros2/ros2_transport.hpp"

namespace {

namespace fs = std::filesystem;
using namespace mbot::ros2;

const fs::path& Scratch() {
  static const fs::path dir = [] {
    mbot::log::SetLevel(mbot::log::Level::kQuiet);
    const fs::path d = fs::temp_directory_path() / ("mbot_fuzz_ros2_" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

// One sample of each type the source decodes.
std::vector<std::pair<std::string, std::vector<uint8_t>>> Samples() {
  LaserScan scan;
  scan.header.frame_id = "lidar_link";
  scan.angle_min = -3.14159f, scan.angle_increment = 0.0175f, scan.angle_max = scan.angle_min + 0.0175f * 15;
  scan.time_increment = 0.0001f, scan.range_min = 0.15f, scan.range_max = 12.0f;
  scan.ranges.assign(16, 1.5f), scan.ranges[3] = NAN;
  Odometry odom;
  odom.header.frame_id = "odom", odom.child_frame_id = "base_footprint", odom.pose.position.x = 0.5;
  TFMessage tf;
  TransformStamped t;
  t.header.frame_id = "base_link", t.child_frame_id = "lidar_link", t.transform.rotation = FromYaw(M_PI);
  tf.transforms = {t};
  PoseStamped pose;
  pose.header.frame_id = "map";
  return {{kLaserScanType, Encode(scan)},
          {kOdometryType, Encode(odom)},
          {kImuType, Encode(Imu{})},
          {kTwistType, Encode(Twist{{0.2, 0, 0}, {0, 0, 0.5}})},
          {kTFMessageType, Encode(tf)},
          {kPoseStampedType, Encode(pose)},
          {kPoseWithCovarianceStampedType, Encode(PoseWithCovarianceStamped{})}};
}

void WriteSeeds(const fs::path& dir) {
  const auto samples = Samples();
  for (const std::string compression : {"zstd", ""}) {
    McapWriterOptions o;
    o.compression = compression;
    o.chunk_size = 512;
    const std::string path =
        (dir / ("seed_bag_" + (compression.empty() ? std::string("plain") : compression))).string();
    McapWriter w(path, o);
    std::vector<uint16_t> channels;
    const char* topics[] = {"/scan", "/odom", "/imu", "/cmd_vel", "/tf_static", "/ground_truth", "/amcl_pose"};
    for (size_t i = 0; i < samples.size(); ++i) {
      channels.push_back(w.AddChannel(w.AddSchema(samples[i].first, "ros2msg", Definition(samples[i].first)), topics[i],
                                      "cdr", {{"offered_qos_profiles", ""}}));
    }
    for (int k = 0; k < 4; ++k) {
      for (size_t i = 0; i < samples.size(); ++i)
        w.Write(channels[i], uint64_t(k * 10 + i) * 1000000, 0, samples[i].second);
    }
    w.Close();
  }
  // The CDR target's seeds: one of each decoder's messages, the selector byte first (Cdr below).
  std::vector<std::vector<uint8_t>> cdr;
  for (const auto& sample : samples) cdr.push_back(sample.second);
  OccupancyGrid grid;
  grid.info.resolution = 0.05f, grid.info.width = 3, grid.info.height = 2;
  grid.data = {-1, 0, 100, 0, 0, 100};
  cdr.push_back(Encode(grid));
  cdr.push_back(Encode(String{"exploring"}));
  cdr.push_back(Encode(Encoders{{1, 2}, {100, -100, 0}, {5, -5, 0}, 20000}));
  cdr.push_back(Encode(MotorVelocity{{1.5f, -1.5f, 0.0f}}));
  AprilTagDetectionArray tags;
  tags.header.frame_id = "camera";
  AprilTagDetection d;
  d.family = "tagCustom48h12", d.id = 3, d.decision_margin = 80.0f;
  d.centre = {320, 240}, d.corners = {300, 220, 340, 220, 340, 260, 300, 260},
  d.homography = {20, 0, 320, 0, 20, 240, 0, 0, 1};
  tags.detections = {d, d};
  cdr.push_back(Encode(tags));
  for (size_t i = 0; i < cdr.size(); ++i) {
    std::vector<uint8_t> input(1, static_cast<uint8_t>(i));
    input.insert(input.end(), cdr[i].begin(), cdr[i].end());
    std::ofstream((dir / ("seed_cdr_" + std::to_string(i))).string(), std::ios::binary)
        .write(reinterpret_cast<const char*>(input.data()), static_cast<std::streamsize>(input.size()));
  }
}

// ROS 1 bags of a real bag's first messages, one per chunk compression.
std::string Ros1Field(const std::string& name, const std::string& value) {
  const std::string f = name + "=" + value;
  const uint32_t n = uint32_t(f.size());
  return std::string(reinterpret_cast<const char*>(&n), 4) + f;
}
std::string Ros1U32(uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); }
std::string Ros1Record(const std::string& header, const std::string& data) {
  return Ros1U32(uint32_t(header.size())) + header + Ros1U32(uint32_t(data.size())) + data;
}

void WriteRos1Seeds(const fs::path& dir, const std::string& from) {
  Ros1BagReader in(from);
  McapMessage m;
  std::map<uint32_t, int> taken;
  std::string records;
  for (int n = 0; n < 400 && in.Next(&m); ++n) {
    if (taken[m.channel_id]++ >= 3) continue;
    if (taken[m.channel_id] == 1) {
      const Ros1Connection& c = in.connections().at(m.channel_id);
      records += Ros1Record(Ros1Field("op", "\x07") + Ros1Field("conn", Ros1U32(c.id)) + Ros1Field("topic", c.topic),
                            Ros1Field("topic", c.topic) + Ros1Field("type", c.type) + Ros1Field("md5sum", c.md5sum));
    }
    const std::string time =
        Ros1U32(uint32_t(m.log_time_ns / 1000000000)) + Ros1U32(uint32_t(m.log_time_ns % 1000000000));
    records += Ros1Record(Ros1Field("op", "\x02") + Ros1Field("conn", Ros1U32(m.channel_id)) + Ros1Field("time", time),
                          std::string(m.data.begin(), m.data.end()));
  }
  for (const std::string compression : {"none", "bz2", "lz4"}) {
    std::string packed = records;
    if (compression == "bz2") {
      packed.resize(records.size() + records.size() / 100 + 600);
      unsigned int n = unsigned(packed.size());
      BZ2_bzBuffToBuffCompress(packed.data(), &n, const_cast<char*>(records.data()), unsigned(records.size()), 9, 0, 0);
      packed.resize(n);
    } else if (compression == "lz4") {
      packed.resize(LZ4F_compressFrameBound(records.size(), nullptr));
      packed.resize(LZ4F_compressFrame(packed.data(), packed.size(), records.data(), records.size(), nullptr));
    }
    const std::string bag =
        "#ROSBAG V2.0\n" + Ros1Record(Ros1Field("op", "\x05") + Ros1Field("compression", compression) +
                                          Ros1Field("size", Ros1U32(uint32_t(records.size()))),
                                      packed);
    std::ofstream((dir / ("seed_ros1_" + compression)).string(), std::ios::binary)
        .write(bag.data(), std::streamsize(bag.size()));
  }
}

[[maybe_unused]] void Ros1(const uint8_t* d, size_t n) {
  const std::string path = (Scratch() / "in.bag").string();
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(d), static_cast<std::streamsize>(n));
  mbot::msgs::SourceOptions o;
  o.type = "ros1_bag";
  o.path = path;
  auto source = mbot::msgs::OpenSource(o);
  while (source->Next()) {
  }
}

[[maybe_unused]] void Mcap(const uint8_t* d, size_t n) {
  const std::string path = (Scratch() / "in.mcap").string();
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(d), static_cast<std::streamsize>(n));
  mbot::msgs::SourceOptions o;
  o.type = "mcap";
  o.path = path;
  auto source = mbot::msgs::OpenSource(o);
  while (source->Next()) {
  }
}

[[maybe_unused]] void Cdr(const uint8_t* d, size_t n) {
  if (n == 0) return;
  const uint8_t* p = d + 1;
  const size_t size = n - 1;
  switch (d[0] % 12) {
    case 0: DecodeLaserScan(p, size); break;
    case 1: DecodeOdometry(p, size); break;
    case 2: DecodeImu(p, size); break;
    case 3: DecodeTwist(p, size); break;
    case 4: DecodeTFMessage(p, size); break;
    case 5: DecodePoseStamped(p, size); break;
    case 6: DecodePoseWithCovarianceStamped(p, size); break;
    case 7: DecodeOccupancyGrid(p, size); break;
    case 8: DecodeString(p, size); break;
    case 9: DecodeEncoders(p, size); break;
    case 10: DecodeMotorVelocity(p, size); break;
    default: DecodeAprilTagDetectionArray(p, size); break;
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  RegisterRos2Transport();
  if (const char* dir = std::getenv("MBOT_FUZZ_SEED_DIR")) {
    WriteSeeds(dir);
    if (const char* bag = std::getenv("MBOT_FUZZ_ROS1_BAG")) WriteRos1Seeds(dir, bag);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    MBOT_FUZZ_TARGET(data, size);
  } catch (const std::exception&) {
    // Rejected with a message: what a parser should do with bad input.
  }
  return 0;
}
