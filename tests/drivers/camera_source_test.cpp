// The camera source on an image folder: frames in name order, grey, stamped 1/fps apart; an
// image whose header passes but which OpenCV cannot take as 8-bit skipped with a warning and
// counted; a file that is no image, claims a size beyond what is read or is cut short refused at
// load, naming the file; paths that are nothing it can read named.
#include "camera_source.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "mbot/drivers/source_options.hpp"
#include "test_util.hpp"

namespace mbot::drivers {

using namespace msgs;  // the event vocabulary
namespace {

TEST(CameraSourceTest, ReplaysAFolderInNameOrderAndSkipsWhatItCannotTake) {
  const std::string dir = test::TempPath("camera_frames");
  std::filesystem::create_directories(dir);
  cv::imwrite(dir + "/b.png", cv::Mat(48, 64, CV_8UC3, cv::Scalar(10, 20, 30)));
  cv::imwrite(dir + "/a.png", cv::Mat(48, 64, CV_8UC1, cv::Scalar(7)));
  cv::imwrite(dir + "/c.jpg", cv::Mat(30, 40, CV_8UC1, cv::Scalar(200)));
  {  // a PNG whose header and end are whole but whose pixel data is corrupt: OpenCV decodes nothing
    std::vector<uchar> png;
    cv::imencode(".png", cv::Mat(8, 8, CV_8UC1, cv::Scalar(7)), png);
    std::string bytes(png.begin(), png.end());
    const size_t idat = bytes.find("IDAT");
    for (size_t k = idat + 4; k < idat + 12; ++k) bytes[k] = static_cast<char>(bytes[k] ^ 0x5a);
    std::ofstream(dir + "/d_corrupt.png", std::ios::binary) << bytes;
  }
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
  EXPECT_EQ(src->diagnostics().rejected_messages, 1);  // d_corrupt.png
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

// What no decoder should be handed: refused when the source opens, naming the file and why.
TEST(CameraSourceTest, RefusesHostileImagesAtLoadNamingTheFile) {
  auto refused = [](const std::string& name, const std::string& bytes, const std::string& why) {
    const std::string dir = test::TempPath("hostile_" + name);
    std::filesystem::create_directories(dir);
    cv::imwrite(dir + "/a_good.png", cv::Mat(8, 8, CV_8UC1, cv::Scalar(7)));
    std::ofstream(dir + "/" + name, std::ios::binary) << bytes;
    SourceOptions o;
    o.type = "camera";
    o.path = dir;
    try {
      OpenSource(o);
      ADD_FAILURE() << name << " was not refused";
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(name), std::string::npos) << what;
      EXPECT_NE(what.find(why), std::string::npos) << what;
    }
  };
  // A PNG whose IHDR claims 20000 x 20000 (the image that killed detect_tags at ~1 GB).
  std::vector<uchar> png;
  cv::imencode(".png", cv::Mat(4, 4, CV_8UC1, cv::Scalar(0)), png);
  std::string big(png.begin(), png.end());
  for (int k = 0; k < 2; ++k) {
    const uint32_t v = 20000;
    for (int b = 0; b < 4; ++b) big[16 + 4 * k + b] = static_cast<char>((v >> (24 - 8 * b)) & 0xff);
  }
  refused("huge.png", big, "20000 x 20000 px is larger than images are read");
  // A JPEG cut short (libjpeg would decode a grey half and say so only on stderr).
  std::vector<uchar> jpg;
  cv::imencode(".jpg", cv::Mat(64, 64, CV_8UC1, cv::Scalar(90)), jpg);
  refused("cut.jpg", std::string(jpg.begin(), jpg.begin() + static_cast<long>(jpg.size() / 2)), "truncated JPEG");
  // A JPEG whose frame header claims 60000 x 60000.
  std::string wide(jpg.begin(), jpg.end());
  for (size_t at = 2; at + 8 < wide.size(); ++at) {
    if (static_cast<uint8_t>(wide[at]) == 0xff && static_cast<uint8_t>(wide[at + 1]) == 0xc0) {
      wide[at + 5] = wide[at + 7] = static_cast<char>(60000 >> 8);
      wide[at + 6] = wide[at + 8] = static_cast<char>(60000 & 0xff);
      break;
    }
  }
  refused("wide.jpg", wide, "60000 x 60000 px");
  refused("cut.png", std::string(png.begin(), png.end() - 5), "truncated PNG");
  refused("bad.png", std::string("\x01\x02\x03", 3), "not an image");
  refused("zero.bmp", std::string("BM") + std::string(30, '\0'), "size of 0 x 0");
}

}  // namespace
}  // namespace mbot::drivers
