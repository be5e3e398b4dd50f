// config/vision_live.ini end to end on rendered frames: camera source (an image folder) → tag
// sightings → the LCM bridge, and an lcm_log output (in-process memq://). What went out on
// MBOT_APRILTAG_ARRAY, read back from the recorded log, holds every tag at its true place.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "../regression/run_config.hpp"
#include "mbot/drivers/source_options.hpp"
#include "mbot/vision/apriltag_detector.hpp"
#include "../vision/render_tags.hpp"

namespace mbot::app {
namespace {

// The shipped nominal camera (datasets/camera/mbot_camera_640x480.yaml).
const cv::Matx33d kK(530, 0, 320, 0, 530, 240, 0, 0, 1);
constexpr double kTagSize = 0.054;

struct Truth {
  int id;
  cv::Vec3d rvec, t;
};

// The tags drawn where `tags` puts them (tag frame in the camera frame) on one grey frame.
cv::Mat Render(const std::vector<Truth>& tags) {
  cv::Mat frame(480, 640, CV_8UC1, cv::Scalar(128));
  for (const Truth& tag : tags) {
    cv::Matx33d R;
    cv::Rodrigues(tag.rvec, R);
    vision::test::DrawTag(&frame, kK, kTagSize, tag.id, R, tag.t);
  }
  return frame;
}

TEST(VisionLiveConfig, PublishesEveryTagWhereItIsAsTheBotlabsArray) {
  const std::vector<std::vector<Truth>> frames = {
      {{1, {0.2, -0.1, 0.05}, {-0.10, 0.02, 0.45}}, {2, {-0.1, 0.3, 0.0}, {0.12, -0.01, 0.6}}},
      {{3, {0.0, 0.0, 0.4}, {0.0, 0.05, 0.35}}},
      {},  // a frame with no tag: an empty array goes out
      {{1, {0.3, 0.2, -0.3}, {0.05, 0.0, 0.8}}}};
  const std::string dir = ::testing::TempDir() + "/vision_live_frames";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  for (size_t k = 0; k < frames.size(); ++k) {
    cv::imwrite(dir + "/frame" + std::to_string(k) + ".png", Render(frames[k]));
  }
  const std::string json = RunConfig("vision_live.ini", "vision_live",
                                     {"source.path=" + dir, "bridge.url=memq://", "tags.decimate=1"}, "sightings.json");
  ASSERT_FALSE(json.empty());
  EXPECT_EQ(Get(json, {"frames"}), 4);
  EXPECT_EQ(Get(json, {"sightings"}), 4);

  msgs::SourceOptions o;
  o.path = ::testing::TempDir() + "/vision_live/sightings.log";
  auto log = msgs::OpenSource(o);
  size_t k = 0;
  while (auto ev = log->Next()) {
    ASSERT_EQ(ev->channel, "MBOT_APRILTAG_ARRAY");
    ASSERT_EQ(ev->kind, msgs::EventKind::kTagSightings);
    ASSERT_LT(k, frames.size());
    EXPECT_EQ(ev->stamp_us, static_cast<int64_t>(std::llround(k * 1e6 / 15.0)));  // camera_fps = 15
    const auto& got = std::get<msgs::TagSightings>(ev->payload).tags;
    ASSERT_EQ(got.size(), frames[k].size()) << "frame " << k;
    for (const Truth& truth : frames[k]) {
      const auto it = std::find_if(got.begin(), got.end(), [&](const auto& s) { return s.id == truth.id; });
      ASSERT_NE(it, got.end()) << "tag " << truth.id << " in frame " << k;
      const cv::Vec3d position(it->x_m, it->y_m, it->z_m);
      EXPECT_LT(cv::norm(position - truth.t), 0.01) << "tag " << truth.id << " in frame " << k << ": " << position;
    }
    ++k;
  }
  EXPECT_EQ(k, frames.size());
}

}  // namespace
}  // namespace mbot::app
