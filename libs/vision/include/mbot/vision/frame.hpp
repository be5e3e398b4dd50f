// A camera frame of the message vocabulary as an OpenCV image.
#pragma once

#include <opencv2/core.hpp>

#include "mbot/msgs/events.hpp"

namespace mbot::vision {

// The frame's pixels without a copy (valid while the frame's pixels live): CV_8UC1 for grey,
// CV_8UC3 (BGR) for colour; an empty Mat when its size disagrees with its pixels.
cv::Mat FrameImage(const msgs::CameraFrame& frame);

}  // namespace mbot::vision
