// libFuzzer targets for the readers of hand-written inputs (issue 33): arenas, camera files,
// relations files and image folders. Compiled once per target with MBOT_FUZZ_TARGET naming the
// function (tests/fuzz/CMakeLists.txt); a rejection with a std::exception is the reader's job, a
// crash, sanitizer report, hang or allocation beyond libFuzzer's limits is a finding.
// Run one: scripts/fuzz.sh TARGET SECONDS.

#include <cstdint>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

#include <opencv2/core.hpp>

#include "mbot/common/log.hpp"
#include "mbot/drivers/source_options.hpp"
#include "mbot/motion/relations.hpp"
#include "mbot/msgs/events.hpp"
#include "mbot/msgs/source.hpp"
#include "mbot/sim/world.hpp"
#include "mbot/vision/apriltag_detector.hpp"
#include "mbot/vision/camera_calibration.hpp"
#include "mbot/vision/tag_observer.hpp"
#include "scratch.hpp"

namespace {

namespace fs = std::filesystem;

using mbot::fuzz::Scratch;
using mbot::fuzz::WriteFile;

[[maybe_unused]] void Arena(const uint8_t* d, size_t n) {
  mbot::sim::World::ParseArena(std::string(reinterpret_cast<const char*>(d), n), "fuzz.arena");
}

[[maybe_unused]] void CameraYaml(const uint8_t* d, size_t n) {
  const std::string path = WriteFile(Scratch() / "camera.yaml", d, n);
  mbot::vision::ReadCameraYaml(path);
  mbot::vision::IntrinsicsFromYaml(path);
}

[[maybe_unused]] void Relations(const uint8_t* d, size_t n) {
  mbot::motion::ReadRelations(WriteFile(Scratch() / "in.relations", d, n));
}

// The first byte picks the file's name (PNG, JPEG, BMP, PGM, TIFF); the rest is the file, the only
// one of a folder the camera source replays. Frames of up to a megapixel go through the tag
// detector too (larger ones are the source's to refuse or pass, not the detector's to time).
[[maybe_unused]] void ImageFolder(const uint8_t* d, size_t n) {
  if (n == 0) return;
  static const char* const kNames[] = {"in.png", "in.jpg", "in.bmp", "in.pgm", "in.tif"};
  const fs::path dir = Scratch() / "images";
  fs::remove_all(dir);
  fs::create_directories(dir);
  WriteFile(dir / kNames[d[0] % 5], d + 1, n - 1);
  mbot::msgs::SourceOptions o;
  o.path = dir.string();
  o.type = "camera";
  auto src = mbot::msgs::OpenSource(o);
  static const mbot::vision::TagDetector detector{mbot::vision::TagDetectorOptions{}};
  while (auto ev = src->Next()) {
    const auto* f = std::get_if<mbot::msgs::CameraFrame>(&ev->payload);
    if (!f || !f->pixels || static_cast<int64_t>(f->width) * f->height > 1000000) continue;
    if (f->pixels->size() != static_cast<size_t>(f->width) * f->height) continue;
    const cv::Mat image(f->height, f->width, CV_8UC1, const_cast<uint8_t*>(f->pixels->data()));
    detector.Detect(image);
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  mbot::drivers::RegisterDatasetSources();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    MBOT_FUZZ_TARGET(data, size);
  } catch (const std::exception&) {
    // Rejected with a message: what a reader should do with bad input.
  }
  return 0;
}
