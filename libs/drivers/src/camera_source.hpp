// [source] type = camera: 8-bit grey frames as kCameraFrame events. A device (path = its index),
// a video file or a GStreamer pipeline (a path holding '!') through OpenCV's VideoCapture; or a
// folder of images (sorted by name) or one image, replayed 1/fps apart from time 0. A device's
// frames carry the wall-clock time; one that stops delivering ends the stream with an error in the
// log. An unreadable image is skipped with a warning naming it and counted.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "mbot/msgs/source.hpp"
#include "mbot/drivers/source_options.hpp"

namespace mbot::drivers {

using namespace msgs;  // the event vocabulary

class CameraSource : public Source {
 public:
  // Throws std::runtime_error naming the path when it cannot be opened (no such device, no image).
  explicit CameraSource(const SourceOptions& options);
  ~CameraSource() override;
  std::optional<Event> Next() override;
  double Progress() const override;
  std::string Format() const override;
  std::vector<std::pair<std::string, std::string>> Details() const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Whether `path` is an image file (not .pgm or .ppm: those are maps) or a folder holding images
// (type = auto picks camera for those).
bool IsImageFileOrFolder(const std::string& path);

}  // namespace mbot::drivers
