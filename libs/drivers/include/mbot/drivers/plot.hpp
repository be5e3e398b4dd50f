// Small XY charts as PNG (calibration fits, speed traces): axes with round ticks, series drawn as
// dots or polylines, a legend. Written whole or not at all.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace mbot::drivers {

struct PlotSeries {
  std::vector<double> x, y;  // same length; non-finite points are skipped
  uint8_t r = 0, g = 0, b = 0;
  bool points = false;  // dots instead of a polyline
  std::string label;    // in the legend when non-empty
};

struct PlotOptions {
  std::string title, x_label, y_label;
  int width = 900, height = 600;
};

// Throws std::runtime_error naming the path when it cannot be written, or when no series has a
// finite point.
void WritePlotPng(const std::vector<PlotSeries>& series, const PlotOptions& options, const std::string& path);

}  // namespace mbot::drivers
