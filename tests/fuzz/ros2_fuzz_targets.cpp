// libFuzzer targets of the ROS 2 transport's parsers (libs/ros2 only, so they build in a minute):
//   mcap  a file given to the `mcap` source (McapReader, chunks, CRCs, every decoder, /tf_static);
//   cdr   the first byte picks a message type, the rest is its CDR payload.
// With MBOT_FUZZ_SEED_DIR set, LLVMFuzzerInitialize writes the seeds there first: small bags of
// every message type (zstd-compressed and plain chunks) and each type's encoding (scripts/fuzz.sh).
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "mbot/common/log.hpp"
#include "mbot/msgs/source.hpp"
#include "mbot/ros2/definitions.hpp"
#include "mbot/ros2/mcap_writer.hpp"
#include "mbot/ros2/messages.hpp"
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
  for (size_t i = 0; i < samples.size(); ++i) {
    std::vector<uint8_t> input(1, static_cast<uint8_t>(i));
    input.insert(input.end(), samples[i].second.begin(), samples[i].second.end());
    std::ofstream((dir / ("seed_cdr_" + std::to_string(i))).string(), std::ios::binary)
        .write(reinterpret_cast<const char*>(input.data()), static_cast<std::streamsize>(input.size()));
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
  switch (d[0] % 7) {
    case 0: DecodeLaserScan(p, size); break;
    case 1: DecodeOdometry(p, size); break;
    case 2: DecodeImu(p, size); break;
    case 3: DecodeTwist(p, size); break;
    case 4: DecodeTFMessage(p, size); break;
    case 5: DecodePoseStamped(p, size); break;
    default: DecodePoseWithCovarianceStamped(p, size); break;
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  RegisterRos2Transport();
  if (const char* dir = std::getenv("MBOT_FUZZ_SEED_DIR")) WriteSeeds(dir);
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
