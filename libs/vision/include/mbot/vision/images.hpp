// Images in and out for the camera stages: the views of a folder, an image or a video; colour for
// drawing on; PNGs (any format OpenCV writes) written whole or not at all.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

namespace mbot::vision {

// The views of `path`: every image file of a folder (sorted by name; .png .jpg .jpeg .bmp .pgm
// .ppm .tif .tiff), one image file, or every `every`-th frame of a video. Throws std::runtime_error
// naming the path when nothing can be read.
std::vector<std::pair<std::string, cv::Mat>> ReadViews(const std::string& path, int every = 1);

// An 8-bit image as 3-channel BGR (grey and BGRA converted, BGR copied), to draw on in colour.
cv::Mat ToBgr(const cv::Mat& image);

// Writes `image` to `path` (format by extension) through a temporary file; throws
// std::runtime_error naming the path when OpenCV cannot write it.
void WriteImage(const cv::Mat& image, const std::string& path);

}  // namespace mbot::vision
