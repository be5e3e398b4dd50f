#include "camera_source.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <filesystem>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "mbot/common/log.hpp"
#include "mbot/drivers/image_header.hpp"

namespace mbot::drivers {

using namespace msgs;  // the event vocabulary
namespace {

namespace fs = std::filesystem;

bool IsImageName(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  for (const char* e : {".png", ".jpg", ".jpeg", ".bmp", ".pgm", ".ppm", ".tif", ".tiff"}) {
    if (ext == e) return true;
  }
  return false;
}

bool IsDeviceIndex(const std::string& path) {
  return !path.empty() && path.size() <= 3 &&
         std::all_of(path.begin(), path.end(), [](unsigned char c) { return std::isdigit(c); });
}

int64_t WallClockUs() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

bool IsImageFileOrFolder(const std::string& path) {
  std::error_code ec;
  if (fs::is_regular_file(path, ec)) {
    // A .pgm or .ppm is a map (map_server's PGM + YAML) unless the type is set to camera.
    const std::string ext = fs::path(path).extension().string();
    return IsImageName(path) && ext != ".pgm" && ext != ".ppm";
  }
  if (!fs::is_directory(path, ec)) return false;
  for (const auto& e : fs::directory_iterator(path, ec)) {
    if (e.is_regular_file() && IsImageName(e.path())) return true;
  }
  return false;
}

struct CameraSource::Impl {
  CameraSourceOptions o;
  std::string path;
  std::vector<std::string> files;  // image replay
  size_t next_file = 0;
  cv::VideoCapture capture;  // device, video or pipeline
  bool device = false;
  int64_t frames = 0, unreadable = 0, total_frames = 0;
  std::string ended;  // why a device's stream ended, for the summary

  Event Frame(const cv::Mat& image, int64_t t_us, const std::string& name) {
    cv::Mat out;  // grey, or BGR when asked for colour and the image has it
    if (image.channels() == 1) {
      out = image;
    } else if (o.color) {
      if (image.channels() == 4) {
        cv::cvtColor(image, out, cv::COLOR_BGRA2BGR);
      } else {
        out = image;
      }
    } else {
      cv::cvtColor(image, out, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
    }
    if (out.depth() != CV_8U) out.convertTo(out, CV_8U);
    CameraFrame f;
    f.width = out.cols, f.height = out.rows, f.name = name, f.channels = out.channels();
    const size_t row = static_cast<size_t>(out.cols) * out.channels();
    auto pixels = std::make_shared<std::vector<uint8_t>>(row * out.rows);
    for (int y = 0; y < out.rows; ++y) std::copy_n(out.ptr<uint8_t>(y), row, pixels->data() + y * row);
    f.pixels = std::move(pixels);
    Event ev;
    ev.kind = EventKind::kCameraFrame;
    ev.channel = o.channel;
    ev.t_us = ev.stamp_us = t_us;
    ev.payload = std::move(f);
    ++frames;
    return ev;
  }
  int64_t ReplayTime(int64_t k) const { return static_cast<int64_t>(std::llround(k * 1e6 / o.fps)); }
};

CameraSource::CameraSource(const SourceOptions& options) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.o = ExtraOr<CameraSourceOptions>(options);
  m.path = options.path;
  std::error_code ec;
  if (fs::is_directory(m.path, ec)) {
    for (const auto& e : fs::directory_iterator(m.path, ec)) {
      if (e.is_regular_file() && IsImageName(e.path())) m.files.push_back(e.path().string());
    }
    std::sort(m.files.begin(), m.files.end());
    if (m.files.empty()) throw std::runtime_error("camera source: no image in folder " + m.path);
  } else if (fs::is_regular_file(m.path, ec) && IsImageName(m.path)) {
    m.files = {m.path};
  } else if (IsDeviceIndex(m.path)) {
    m.device = true;
    if (!m.capture.open(std::stoi(m.path))) throw std::runtime_error("camera source: cannot open camera " + m.path);
    m.capture.set(cv::CAP_PROP_FRAME_WIDTH, m.o.width);
    m.capture.set(cv::CAP_PROP_FRAME_HEIGHT, m.o.height);
    m.capture.set(cv::CAP_PROP_FPS, m.o.fps);
  } else {
    const bool pipeline = m.path.find('!') != std::string::npos;
    const bool opened = pipeline ? m.capture.open(m.path, cv::CAP_GSTREAMER) : m.capture.open(m.path);
    if (!opened)
      throw std::runtime_error("camera source: cannot open " + m.path +
                               " (not an image, a folder of "
                               "images, a camera index, a video OpenCV reads or a GStreamer pipeline)");
    m.device = pipeline;  // a pipeline is live; a video file replays
    if (!pipeline) m.total_frames = static_cast<int64_t>(m.capture.get(cv::CAP_PROP_FRAME_COUNT));
  }
  // Every file is checked before the first is decoded: a size beyond what is read, a file cut short
  // or no image at all stops the run at load, naming the file.
  for (const std::string& file : m.files) {
    try {
      CheckImageFile(file);
    } catch (const std::exception& e) {
      throw std::runtime_error(std::string("camera source: ") + e.what());
    }
  }
  channels_[m.o.channel] = ChannelInfo{"8-bit grey image", "", EventKind::kCameraFrame, true};
}

CameraSource::~CameraSource() = default;

std::optional<Event> CameraSource::Next() {
  Impl& m = *impl_;
  while (m.next_file < m.files.size()) {
    const std::string& file = m.files[m.next_file++];
    // Grey straight from the file: a JPEG's own luma, as the AprilTag library's reader takes it (a
    // colour decode converted back to grey moves tag corners by up to 0.3 px on its test photos).
    cv::Mat image;
    try {
      image = cv::imread(file, m.o.color ? cv::IMREAD_UNCHANGED : cv::IMREAD_GRAYSCALE | cv::IMREAD_IGNORE_ORIENTATION);
    } catch (const cv::Exception& e) {  // OpenCV's own limits, in a message naming no file
      throw std::runtime_error("camera source: " + file + ": OpenCV cannot read it (" + e.msg + ")");
    }
    if (image.empty() || image.depth() != CV_8U) {
      mbot::log::Warn("camera source: skipped " + file + " (not an 8-bit image OpenCV can read)");
      ++m.unreadable;
      ++diagnostics_.rejected_messages;
      continue;
    }
    return m.Frame(image, m.ReplayTime(m.frames), fs::path(file).filename().string());
  }
  if (!m.capture.isOpened()) return std::nullopt;
  const auto start = std::chrono::steady_clock::now();
  cv::Mat image;
  while (!m.capture.read(image) || image.empty()) {
    if (!m.device) return std::nullopt;  // the end of a video file
    const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (waited >= m.o.timeout_s) {
      m.ended = "camera " + m.path + " stopped delivering frames (none for " + std::to_string(m.o.timeout_s) +
                " s after " + std::to_string(m.frames) + " frames)";
      mbot::log::Error(m.ended);
      m.capture.release();
      return std::nullopt;
    }
  }
  if (m.device) return m.Frame(image, WallClockUs(), m.path);
  const double msec = m.capture.get(cv::CAP_PROP_POS_MSEC);
  const int64_t t = msec > 0 ? static_cast<int64_t>(msec * 1e3) : m.ReplayTime(m.frames);
  return m.Frame(image, t, "frame " + std::to_string(m.frames));
}

double CameraSource::Progress() const {
  const Impl& m = *impl_;
  if (!m.files.empty()) return static_cast<double>(m.next_file) / m.files.size();
  if (m.total_frames > 0) return std::min(1.0, static_cast<double>(m.frames) / m.total_frames);
  return 0.0;
}

std::string CameraSource::Format() const {
  const Impl& m = *impl_;
  return !m.files.empty() ? "images" : m.device ? "camera" : "video";
}

std::vector<std::pair<std::string, std::string>> CameraSource::Details() const {
  const Impl& m = *impl_;
  std::vector<std::pair<std::string, std::string>> d = {{"frames", std::to_string(m.frames)},
                                                        {"unreadable images", std::to_string(m.unreadable)}};
  if (!m.ended.empty()) d.emplace_back("ended", m.ended);
  return d;
}

}  // namespace mbot::drivers
