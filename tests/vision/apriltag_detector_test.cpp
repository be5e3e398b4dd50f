#include "mbot/vision/apriltag_detector.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace mbot::vision {
namespace {

// Tag 7 of tag36h11 drawn by the library (10 cells with the white border), 12 px a cell, pasted on a
// grey 640 x 480 frame at (200, 100): its black square's outer corners lie 1 cell in, 8 cells wide.
TEST(AprilTagDetectorTest, FindsARenderedTagWithItsIdAndCorners) {
  const cv::Mat tag = TagImage("tag36h11", 7, 12);
  ASSERT_EQ(tag.cols, 120);
  cv::Mat frame(480, 640, CV_8UC1, cv::Scalar(128));
  tag.copyTo(frame(cv::Rect(200, 100, tag.cols, tag.rows)));
  for (double decimate : {1.0, 2.0}) {
    TagDetectorOptions o;
    o.decimate = decimate;
    const TagDetector detector(o);
    const std::vector<TagDetection> found = detector.Detect(frame);
    ASSERT_EQ(found.size(), 1u) << "decimate " << decimate;
    EXPECT_EQ(found[0].id, 7);
    EXPECT_EQ(found[0].hamming, 0);
    EXPECT_GT(found[0].margin, 50.0);
    EXPECT_NEAR(found[0].center.x, 200 + 60, 0.5);
    EXPECT_NEAR(found[0].center.y, 100 + 60, 0.5);
    // The corners of the black square (x 212..308, y 112..208, as pixel edges).
    for (const cv::Point2d& c : found[0].corners) {
      EXPECT_TRUE(std::abs(c.x - 212) < 1.0 || std::abs(c.x - 308) < 1.0) << c;
      EXPECT_TRUE(std::abs(c.y - 112) < 1.0 || std::abs(c.y - 208) < 1.0) << c;
    }
  }
  // A colour frame reads the same.
  cv::Mat colour;
  cv::cvtColor(frame, colour, cv::COLOR_GRAY2BGR);
  EXPECT_EQ(TagDetector(TagDetectorOptions{}).Detect(colour).size(), 1u);
}

// Every family Debian's library has, the ROS 2 MBot's tagCustom48h12 among them: a rendered tag is
// found with its id, and the homography maps the tag's centre (0, 0) to the detection's centre.
TEST(AprilTagDetectorTest, EveryFamilyFindsItsOwnTag) {
  const std::vector<std::string> families = TagFamilies();
  EXPECT_NE(std::find(families.begin(), families.end(), "tagCustom48h12"), families.end());
  for (const std::string& family : families) {
    SCOPED_TRACE(family);
    const cv::Mat tag = TagImage(family, 3, 12);
    cv::Mat frame(480, 640, CV_8UC1, cv::Scalar(255));
    tag.copyTo(frame(cv::Rect(200, 100, tag.cols, tag.rows)));
    TagDetectorOptions o;
    o.family = family;
    o.decimate = 1;
    const std::vector<TagDetection> found = TagDetector(o).Detect(frame);
    ASSERT_EQ(found.size(), 1u);
    EXPECT_EQ(found[0].id, 3);
    EXPECT_NEAR(found[0].center.x, 200 + tag.cols / 2.0, 1.0);
    EXPECT_NEAR(found[0].center.y, 100 + tag.rows / 2.0, 1.0);
    const auto& h = found[0].homography;
    EXPECT_NEAR(h[2] / h[8], found[0].center.x, 1e-6);
    EXPECT_NEAR(h[5] / h[8], found[0].center.y, 1e-6);
  }
}

TEST(AprilTagDetectorTest, NothingInABlankFrameAndBadOptionsNamed) {
  EXPECT_TRUE(TagDetector(TagDetectorOptions{}).Detect(cv::Mat(480, 640, CV_8UC1, cv::Scalar(200))).empty());
  TagDetectorOptions o;
  o.family = "tag99h1";
  try {
    TagDetector d(o);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'tag99h1' is not one of: tag36h11"), std::string::npos) << e.what();
  }
  EXPECT_THROW(TagImage("tag36h11", 587, 4), std::invalid_argument);  // tag36h11 has 587 codes
  // A family of 42,211 codes corrects 1 bit by default; 2 would take gigabytes, and is refused.
  o.family = "tagCustom48h12";
  o.max_bits_corrected = 2;
  try {
    TagDetector d(o);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("tagCustom48h12 has 42211 codes"), std::string::npos) << e.what();
  }
  EXPECT_THROW(TagDetector(TagDetectorOptions{}).Detect(cv::Mat()), std::invalid_argument);
}

}  // namespace
}  // namespace mbot::vision
