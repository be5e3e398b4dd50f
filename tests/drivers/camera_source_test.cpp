// The camera source on an image folder: frames in name order, grey, stamped 1/fps apart; an
// unreadable image skipped with a warning and counted; paths that are nothing it can read named.
#include "camera_source.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "mbot/drivers/source_options.hpp"
#include "test_util.hpp"

namespace mbot::drivers {

using namespace msgs;  // the event vocabulary
namespace {

TEST(CameraSourceTest, ReplaysAFolderInNameOrderAndSkipsWhatItCannotRead) {
  const std::string dir = test::TempPath("camera_frames");
  std::filesystem::create_directories(dir);
  cv::imwrite(dir + "/b.png", cv::Mat(48, 64, CV_8UC3, cv::Scalar(10, 20, 30)));
  cv::imwrite(dir + "/a.png", cv::Mat(48, 64, CV_8UC1, cv::Scalar(7)));
  cv::imwrite(dir + "/c.jpg", cv::Mat(30, 40, CV_8UC1, cv::Scalar(200)));
  test::WriteBytes(dir + "/bad.png", {1, 2, 3});
  test::WriteBytes(dir + "/notes.txt", {'h', 'i'});  // not an image name: not even tried
  EXPECT_TRUE(IsImageFileOrFolder(dir));
  EXPECT_EQ(DetectFormat(dir), "camera");
  SourceOptions o;
  o.type = "camera";
  o.path = dir;
  CameraSourceOptions camera;
  camera.fps = 10.0;
  o.extra = camera;
  auto src = OpenSource(o);
  std::vector<Event> frames;
  while (auto ev = src->Next()) frames.push_back(*ev);
  ASSERT_EQ(frames.size(), 3u);
  const char* names[] = {"a.png", "b.png", "c.jpg"};
  for (size_t k = 0; k < 3; ++k) {
    ASSERT_EQ(frames[k].kind, EventKind::kCameraFrame);
    EXPECT_EQ(frames[k].channel, "CAMERA");
    EXPECT_EQ(frames[k].t_us, static_cast<int64_t>(k) * 100000);
    const auto& f = std::get<CameraFrame>(frames[k].payload);
    EXPECT_EQ(f.name, names[k]);
    ASSERT_TRUE(f.pixels);
    EXPECT_EQ(f.pixels->size(), static_cast<size_t>(f.width) * f.height);
  }
  EXPECT_EQ(std::get<CameraFrame>(frames[0].payload).pixels->at(0), 7);
  EXPECT_EQ(std::get<CameraFrame>(frames[2].payload).width, 40);
  EXPECT_EQ(src->diagnostics().rejected_messages, 1);  // bad.png
  EXPECT_DOUBLE_EQ(src->Progress(), 1.0);
}

TEST(CameraSourceTest, WhatCannotBeOpenedIsNamed) {
  SourceOptions o;
  o.type = "camera";
  o.path = test::TempPath("no_such_video.avi");
  try {
    OpenSource(o);
    FAIL() << "opened a missing video";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_video.avi"), std::string::npos) << e.what();
  }
  const std::string empty = test::TempPath("no_images_here");
  std::filesystem::create_directories(empty);
  o.path = empty;
  EXPECT_THROW(OpenSource(o), std::runtime_error);
  // A map_server PGM is a map, not a camera image, for type = auto.
  cv::imwrite(test::TempPath("map.pgm"), cv::Mat(4, 4, CV_8UC1, cv::Scalar(0)));
  EXPECT_FALSE(IsImageFileOrFolder(test::TempPath("map.pgm")));
}

}  // namespace
}  // namespace mbot::drivers
