// Test helper: tag36h11 tags seen by a pinhole camera K, drawn into grey 640 × 480 frames with
// their true projection. A tag's frame (x right, y down the printed tag, z into it) is at (R, t)
// in the camera frame; `tag_size_m` is the black square's side (8 of the tag image's 10 cells).
#pragma once

#include <opencv2/imgproc.hpp>

#include "mbot/vision/apriltag_detector.hpp"

namespace mbot::vision::test {

// Draws tag `id` over `frame` (8-bit grey), leaving the rest as it was.
inline void DrawTag(cv::Mat* frame, const cv::Matx33d& K, double tag_size_m, int id, const cv::Matx33d& R,
                    const cv::Vec3d& t) {
  const cv::Mat texture = TagImage("tag36h11", id, 20);
  const double s = tag_size_m / 160.0, half = texture.cols / 2.0;
  const cv::Matx33d S(s, 0, -half * s, 0, s, -half * s, 0, 0, 1);
  const cv::Matx33d Rt(R(0, 0), R(0, 1), t[0], R(1, 0), R(1, 1), t[1], R(2, 0), R(2, 1), t[2]);
  const cv::Mat H(K * Rt * S);
  cv::Mat warped, mask;
  cv::warpPerspective(texture, warped, H, frame->size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(128));
  cv::warpPerspective(cv::Mat(texture.size(), CV_8UC1, cv::Scalar(255)), mask, H, frame->size());
  warped.copyTo(*frame, mask);
}

// One tag on a mid-grey 640 × 480 frame.
inline cv::Mat RenderTag(const cv::Matx33d& K, double tag_size_m, int id, const cv::Matx33d& R, const cv::Vec3d& t) {
  cv::Mat frame(480, 640, CV_8UC1, cv::Scalar(128));
  DrawTag(&frame, K, tag_size_m, id, R, t);
  return frame;
}

}  // namespace mbot::vision::test
