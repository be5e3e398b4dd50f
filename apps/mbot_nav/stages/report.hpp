// Helpers the stages share for their printed tables and JSON reports.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

namespace mbot::app {

inline double Median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

inline std::string JsonString(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (static_cast<unsigned char>(c) < 0x20) {
      o += ' ';
      continue;
    }
    o += c;
  }
  return o + "\"";
}

// One TUM trajectory line, "t x y z qx qy qz qw", for a planar pose at t seconds.
inline std::string TumLine(double t_s, double x, double y, double theta) {
  char line[160];
  std::snprintf(line, sizeof line, "%.6f %.6f %.6f 0 0 0 %.9f %.9f\n", t_s, x, y, std::sin(theta / 2), std::cos(theta / 2));
  return line;
}

// A number for JSON: non-finite values become null.
inline std::string Num(double v, int precision = 6) {
  if (!std::isfinite(v)) return "null";
  std::ostringstream s;
  s << std::setprecision(precision) << v;
  return s.str();
}

// min / mean / median / max / std of a sample, the form the botlab reports print their timings in.
struct SampleStats {
  size_t count = 0;
  double min = NAN, mean = NAN, median = NAN, max = NAN, std = NAN;

  static SampleStats Of(const std::vector<double>& v) {
    SampleStats s;
    s.count = v.size();
    if (v.empty()) return s;
    s.min = *std::min_element(v.begin(), v.end());
    s.max = *std::max_element(v.begin(), v.end());
    double sum = 0.0;
    for (double x : v) sum += x;
    s.mean = sum / v.size();
    double var = 0.0;
    for (double x : v) var += (x - s.mean) * (x - s.mean);
    s.std = std::sqrt(var / v.size());
    s.median = Median(v);
    return s;
  }
  std::string Json() const {
    return "{\"count\": " + std::to_string(count) + ", \"min\": " + Num(min) + ", \"mean\": " + Num(mean) +
           ", \"median\": " + Num(median) + ", \"max\": " + Num(max) + ", \"std\": " + Num(std) + "}";
  }
};

}  // namespace mbot::app
