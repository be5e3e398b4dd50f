// The dataset files libs/drivers reads as sources (MRPT rawlogs, CARMEN logs, map files, the botlab
// A* cases, Moving AI scenarios, motor calibration CSVs, camera frames) and their own [source] keys.
// The types are registered in the source registry (libs/msgs) by RegisterDatasetSources().
#pragma once

#include <string>

#include "mbot/msgs/source.hpp"
#include "mbot/msgs/topics.hpp"

namespace mbot::drivers {

// [source] type = camera: frames from a camera (path = a device index), a video file or a
// GStreamer pipeline (OpenCV's VideoCapture), or an image folder or file replayed at `fps`.
struct CameraSourceOptions {
  double fps = 15.0;  // replay: frames are stamped 1/fps apart; a device is asked for this rate
  int width = 640;    // a device is asked for this size
  int height = 480;
  double timeout_s = 2.0;  // a device that delivers no frame for this long ends the stream (reported)
  bool color = false;      // BGR frames (colour images stay colour) instead of grey
  std::string channel = msgs::topics::kCamera;
};

// [source] type = carmen.
struct CarmenOptions {
  // CARMEN logs with old FLASER lines give no range limit; beams at or beyond it are no-returns.
  double max_range_m = 81.0;
  // CARMEN records in the order of their stamps (stamp), or in the file's order (file) for logs whose
  // stamps are arrival times that run backwards (the raw Intel log): each record's event time is then
  // its stamp held non-decreasing along the file, and its stamp is kept as the message's own. auto:
  // file order when the stamps run backwards by less than `kAutoOrderJitterS` only, else stamp order.
  enum class Order { kStamp, kFile, kAuto } order = Order::kAuto;
  static constexpr double kAutoOrderJitterS = 2.0;
};

// Registers the dataset types (idempotent): astar_cases, movingai, map, rawlog, motor_csv, carmen, camera.
void RegisterDatasetSources();

}  // namespace mbot::drivers
