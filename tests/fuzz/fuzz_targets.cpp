// libFuzzer targets, one per parser: this file is compiled once per target with MBOT_FUZZ_TARGET
// naming the function below that LLVMFuzzerTestOneInput calls (tests/fuzz/CMakeLists.txt).
// A parser may reject its input with a std::exception (that is its job); a crash, a sanitizer
// report, a leak, a hang or an allocation beyond libFuzzer's -rss_limit_mb is a finding.
// Run one: scripts/fuzz.sh TARGET SECONDS.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "lcm_messages.hpp"
#include "mbot/lcm/lcm_log.hpp"
#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/drivers/map_io.hpp"
#include "mbot/drivers/source_options.hpp"
#include "mbot/lcm/lcm_sources.hpp"
#include "scratch.hpp"

namespace mbot::mapping {
void RegisterScanRenderer();  // libs/mapping: scan_renderer.cpp
}

namespace {

namespace fs = std::filesystem;

using mbot::fuzz::Scratch;
std::string Write(const std::string& name, const uint8_t* data, size_t size) {
  return mbot::fuzz::WriteFile(Scratch() / name, data, size);
}

// Opens `path` as a source of `type` and reads every event.
void Drain(const std::string& path, const std::string& type) {
  mbot::msgs::SourceOptions o;
  o.path = path;
  o.type = type;
  auto src = mbot::msgs::OpenSource(o);
  while (src->Next()) {
  }
}

// The channels lcm_messages decodes on: the roles the decoder gives them differ.
const char* const kChannels[] = {"LIDAR",     "ODOMETRY",      "MBOT_ODOMETRY", "TRUE_POSE",    "GROUND_TRUTH_POSE",
                                 "SLAM_POSE", "MBOT_ENCODERS", "MBOT_IMU",      "MBOT_VEL_CMD", "MBOT_MOTOR_PWM",
                                 "SLAM_MAP",  "OTHER"};
constexpr size_t kChannelCount = sizeof kChannels / sizeof *kChannels;

[[maybe_unused]] void LcmLog(const uint8_t* d, size_t n) { Drain(Write("in.log", d, n), "lcm_log"); }

// The first byte picks the channel (and so the role the decoder gives it); the rest is the payload.
[[maybe_unused]] void LcmMessages(const uint8_t* d, size_t n) {
  if (n == 0) return;
  const std::string channel = kChannels[d[0] % kChannelCount];
  const mbot::msgs::ChannelRoles roles;
  mbot::msgs::Event event;
  std::string error;
  mbot::lcmio::lcm_adapter::Decode(channel, d + 1, n - 1, roles, &event, &error);
}

[[maybe_unused]] void Rawlog(const uint8_t* d, size_t n) { Drain(Write("in.rawlog", d, n), "rawlog"); }
[[maybe_unused]] void Carmen(const uint8_t* d, size_t n) { Drain(Write("in.clf", d, n), "carmen"); }
[[maybe_unused]] void BotlabMap(const uint8_t* d, size_t n) { mbot::drivers::ReadBotlabMap(Write("in.map", d, n)); }
[[maybe_unused]] void Gridmap(const uint8_t* d, size_t n) { mbot::drivers::ReadMrptGridmap(Write("in.gridmap", d, n)); }
[[maybe_unused]] void Simplemap(const uint8_t* d, size_t n) {
  mbot::drivers::ReadMrptSimplemap(Write("in.simplemap", d, n));
}
[[maybe_unused]] void MovingAiMap(const uint8_t* d, size_t n) { mbot::drivers::ReadMovingAiMap(Write("in.map", d, n)); }

// The YAML up to the first NUL byte, the image after it (saved as the map.pgm the seeds name).
[[maybe_unused]] void PgmYaml(const uint8_t* d, size_t n) {
  size_t split = 0;
  while (split < n && d[split] != 0) ++split;
  const std::string yaml = Write("map.yaml", d, split);
  Write("map.pgm", d + std::min(n, split + 1), n - std::min(n, split + 1));
  mbot::drivers::ReadRosMap(yaml);
}

// A scenario file whose lines name tiny.map, an 8 × 8 map written beside it.
[[maybe_unused]] void MovingAiScenarios(const uint8_t* d, size_t n) {
  static const bool map_written = [] {
    std::ofstream((Scratch() / "tiny.map").string()) << "type octile\nheight 8\nwidth 8\nmap\n"
                                                     << std::string(8, '.') + "\n" + std::string(8, '.') + "\n"
                                                     << "...@@...\n...@@...\n........\n........\n........\n"
                                                     << "........\n";
    return true;
  }();
  (void)map_written;
  Drain(Write("in.map.scen", d, n), "movingai");
}

[[maybe_unused]] void MotorCsv(const uint8_t* d, size_t n) { Drain(Write("in.csv", d, n), "motor_csv"); }

// INI text, then one `--set` override from the text after the first NUL byte, then every section
// read back (the parser's own structure, not a stage's keys).
[[maybe_unused]] void Ini(const uint8_t* d, size_t n) {
  size_t split = 0;
  while (split < n && d[split] != 0) ++split;
  auto config = mbot::config::Config::FromString(std::string(reinterpret_cast<const char*>(d), split), "fuzz.ini",
                                                 Scratch().string());
  if (split + 1 < n) config.Set(std::string(reinterpret_cast<const char*>(d + split + 1), n - split - 1));
  for (const std::string& name : config.SectionNames()) config.GetSection(name);
  config.ToIni();
}

// Seeds for lcm_messages: with MBOT_FUZZ_CARVE=<log>[:<log>…] and MBOT_FUZZ_CARVE_DIR=<folder>, the
// first messages of every channel of those LCM logs are written as inputs (channel byte + payload).
void CarveLcmMessages() {
  const char* logs = std::getenv("MBOT_FUZZ_CARVE");
  const char* dir = std::getenv("MBOT_FUZZ_CARVE_DIR");
  if (!logs || !dir) return;
  std::string list = logs;
  int written = 0;
  for (size_t start = 0; start <= list.size();) {
    const size_t end = std::min(list.find(':', start), list.size());
    const std::string log = list.substr(start, end - start);
    start = end + 1;
    if (log.empty()) continue;
    try {
      mbot::lcmio::LcmLogReader reader(log);
      std::map<std::string, int> per_channel;
      while (auto r = reader.Next()) {
        if (++per_channel[r->channel] > 3) continue;
        size_t index = kChannelCount - 1;  // OTHER
        for (size_t k = 0; k < kChannelCount; ++k) {
          if (r->channel == kChannels[k]) index = k;
        }
        std::vector<uint8_t> input(1, static_cast<uint8_t>(index));
        input.insert(input.end(), r->data.begin(), r->data.end());
        std::ofstream((fs::path(dir) / ("carved_" + std::to_string(written++))).string(), std::ios::binary)
            .write(reinterpret_cast<const char*>(input.data()), static_cast<std::streamsize>(input.size()));
      }
    } catch (const std::exception& e) {
      std::fprintf(stderr, "carve: %s\n", e.what());
    }
  }
  std::fprintf(stderr, "carve: %d messages written to %s\n", written, dir);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  mbot::mapping::RegisterScanRenderer();  // simplemaps are rendered by libs/mapping
  mbot::drivers::RegisterDatasetSources();
  mbot::lcmio::RegisterLcmTransport();
  CarveLcmMessages();
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
