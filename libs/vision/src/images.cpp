#include "mbot/vision/images.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "mbot/common/atomic_file.hpp"

namespace mbot::vision {
namespace {

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

bool IsImageFile(const std::filesystem::path& p) {
  const std::string e = Lower(p.extension().string());
  return e == ".png" || e == ".jpg" || e == ".jpeg" || e == ".bmp" || e == ".pgm" || e == ".ppm" || e == ".tif" ||
         e == ".tiff";
}

}  // namespace

std::vector<std::pair<std::string, cv::Mat>> ReadViews(const std::string& path, int every) {
  namespace fs = std::filesystem;
  std::vector<std::pair<std::string, cv::Mat>> views;
  if (!fs::exists(path)) throw std::runtime_error(path + ": no such file or folder");
  if (fs::is_directory(path)) {
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(path)) {
      if (e.is_regular_file() && IsImageFile(e.path())) files.push_back(e.path());
    }
    std::sort(files.begin(), files.end());
    for (const fs::path& f : files) {
      cv::Mat m = cv::imread(f.string(), cv::IMREAD_UNCHANGED);
      if (m.empty()) throw std::runtime_error(f.string() + ": not a readable image");
      views.emplace_back(f.filename().string(), m);
    }
    if (views.empty()) throw std::runtime_error(path + ": no image files in the folder");
    return views;
  }
  if (IsImageFile(path)) {
    cv::Mat m = cv::imread(path, cv::IMREAD_UNCHANGED);
    if (m.empty()) throw std::runtime_error(path + ": not a readable image");
    views.emplace_back(fs::path(path).filename().string(), m);
    return views;
  }
  cv::VideoCapture video(path);
  if (!video.isOpened())
    throw std::runtime_error(path + ": neither an image, a folder of images nor a video OpenCV can open");
  cv::Mat frame;
  for (int n = 0; video.read(frame); ++n) {
    if (n % std::max(1, every) == 0) views.emplace_back("frame " + std::to_string(n), frame.clone());
  }
  if (views.empty()) throw std::runtime_error(path + ": the video has no frames");
  return views;
}

cv::Mat ToBgr(const cv::Mat& image) {
  cv::Mat bgr;
  if (image.channels() == 1) {
    cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  } else if (image.channels() == 4) {
    cv::cvtColor(image, bgr, cv::COLOR_BGRA2BGR);
  } else {
    bgr = image.clone();
  }
  return bgr;
}

void WriteImage(const cv::Mat& image, const std::string& path) {
  const std::string tmp = TempPathFor(path);
  if (!cv::imwrite(tmp, image)) throw std::runtime_error(path + ": cannot be written");
  CommitFile(tmp, path);
}

}  // namespace mbot::vision
