#include "mbot/vision/apriltag_detector.hpp"

#include <gtest/gtest.h>

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
  EXPECT_THROW(TagDetector(TagDetectorOptions{}).Detect(cv::Mat()), std::invalid_argument);
}

}  // namespace
}  // namespace mbot::vision
