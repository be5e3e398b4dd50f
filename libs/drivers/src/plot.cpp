#include "mbot/drivers/plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "mbot/common/atomic_file.hpp"

namespace mbot::drivers {

namespace {

// A "nice" tick step (1, 2 or 5 × 10^k) giving about `target` ticks over `span`.
double NiceStep(double span, int target) {
  const double raw = span / std::max(1, target);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * mag >= raw) return m * mag;
  }
  return 10.0 * mag;
}

std::string TickLabel(double v, double step) {
  char buf[32];
  const int decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  std::snprintf(buf, sizeof buf, "%.*f", decimals, std::abs(v) < step * 1e-6 ? 0.0 : v);
  return buf;
}

}  // namespace

void WritePlotPng(const std::vector<PlotSeries>& series, const PlotOptions& o, const std::string& path) {
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const auto& s : series) {
    for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      x0 = std::min(x0, s.x[i]), x1 = std::max(x1, s.x[i]);
      y0 = std::min(y0, s.y[i]), y1 = std::max(y1, s.y[i]);
    }
  }
  if (!(x0 <= x1)) throw std::runtime_error(path + ": nothing to plot (no finite point)");
  if (x1 - x0 < 1e-12) x0 -= 0.5, x1 += 0.5;
  if (y1 - y0 < 1e-12) y0 -= 0.5, y1 += 0.5;
  const double xs = NiceStep(x1 - x0, 8), ys = NiceStep(y1 - y0, 6);
  x0 = std::floor(x0 / xs) * xs, x1 = std::ceil(x1 / xs) * xs;
  y0 = std::floor(y0 / ys) * ys, y1 = std::ceil(y1 / ys) * ys;

  const int left = 80, right = 20, top = 40, bottom = 60;
  const int w = std::max(200, o.width), h = std::max(150, o.height);
  cv::Mat img(h, w, CV_8UC3, cv::Scalar(255, 255, 255));
  const auto px = [&](double x) { return left + (x - x0) / (x1 - x0) * (w - left - right); };
  const auto py = [&](double y) { return h - bottom - (y - y0) / (y1 - y0) * (h - top - bottom); };
  const cv::Scalar grid(225, 225, 225), axis(60, 60, 60);
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  for (double x = x0; x <= x1 + xs * 1e-6; x += xs) {
    const int X = static_cast<int>(std::lround(px(x)));
    cv::line(img, {X, top}, {X, h - bottom}, grid, 1);
    cv::putText(img, TickLabel(x, xs), {X - 14, h - bottom + 18}, font, 0.4, axis, 1, cv::LINE_AA);
  }
  for (double y = y0; y <= y1 + ys * 1e-6; y += ys) {
    const int Y = static_cast<int>(std::lround(py(y)));
    cv::line(img, {left, Y}, {w - right, Y}, grid, 1);
    cv::putText(img, TickLabel(y, ys), {8, Y + 4}, font, 0.4, axis, 1, cv::LINE_AA);
  }
  if (x0 < 0 && x1 > 0) cv::line(img, {int(px(0)), top}, {int(px(0)), h - bottom}, axis, 1);
  if (y0 < 0 && y1 > 0) cv::line(img, {left, int(py(0))}, {w - right, int(py(0))}, axis, 1);
  cv::rectangle(img, {left, top}, {w - right, h - bottom}, axis, 1);
  cv::putText(img, o.title, {left, 25}, font, 0.55, axis, 1, cv::LINE_AA);
  cv::putText(img, o.x_label, {(left + w - right) / 2 - 60, h - 15}, font, 0.45, axis, 1, cv::LINE_AA);
  cv::putText(img, o.y_label, {8, top - 8}, font, 0.45, axis, 1, cv::LINE_AA);

  int legend_y = top + 18;
  for (const auto& s : series) {
    const cv::Scalar c(s.b, s.g, s.r);
    cv::Point prev;
    bool have_prev = false;
    for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) {
        have_prev = false;
        continue;
      }
      const cv::Point p(static_cast<int>(std::lround(px(s.x[i]))), static_cast<int>(std::lround(py(s.y[i]))));
      if (s.points) {
        cv::circle(img, p, 2, c, cv::FILLED, cv::LINE_AA);
      } else if (have_prev) {
        cv::line(img, prev, p, c, 2, cv::LINE_AA);
      }
      prev = p, have_prev = true;
    }
    if (!s.label.empty()) {
      if (s.points) {
        cv::circle(img, {left + 18, legend_y - 4}, 3, c, cv::FILLED, cv::LINE_AA);
      } else {
        cv::line(img, {left + 10, legend_y - 4}, {left + 26, legend_y - 4}, c, 2, cv::LINE_AA);
      }
      cv::putText(img, s.label, {left + 32, legend_y}, font, 0.42, axis, 1, cv::LINE_AA);
      legend_y += 18;
    }
  }
  const std::string tmp = TempPathFor(path);
  if (!cv::imwrite(tmp, img)) throw std::runtime_error(path + ": cannot write PNG");
  CommitFile(tmp, path);
}

}  // namespace mbot::drivers
