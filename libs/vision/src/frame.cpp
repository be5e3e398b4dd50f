#include "mbot/vision/frame.hpp"

namespace mbot::vision {

cv::Mat FrameImage(const msgs::CameraFrame& f) {
  if (!f.pixels || f.width < 1 || f.height < 1 || (f.channels != 1 && f.channels != 3) ||
      f.pixels->size() != static_cast<size_t>(f.width) * f.height * f.channels) {
    return cv::Mat();
  }
  return cv::Mat(f.height, f.width, f.channels == 1 ? CV_8UC1 : CV_8UC3, const_cast<uint8_t*>(f.pixels->data()));
}

}  // namespace mbot::vision
