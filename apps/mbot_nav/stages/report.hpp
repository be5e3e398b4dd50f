// Helpers the stages share for their printed tables and JSON reports.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/strings.hpp"
#include "mbot/motion/pose2d.hpp"
#include "mbot/motion/trajectory_error.hpp"

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
  std::snprintf(line, sizeof line, "%.6f %.6f %.6f 0 0 0 %.9f %.9f\n", t_s, x, y, std::sin(theta / 2),
                std::cos(theta / 2));
  return line;
}

// A number for JSON: non-finite values become null.
inline std::string Num(double v, int precision = 6) { return std::isfinite(v) ? Significant(v, precision) : "null"; }

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

// Trajectory-error JSON, the layout metrics.json files share: per axis RMSE / mean / max / std,
// heading in degrees, the final-pose error and the alignment applied.
inline std::string PoseJson(const motion::Pose2D& p) {
  return "{\"x\": " + Num(p.x) + ", \"y\": " + Num(p.y) + ", \"theta\": " + Num(p.theta) + "}";
}

inline std::string StatsJson(const motion::ErrorStats& s, double scale = 1.0) {
  return "{\"rmse\": " + Num(s.rmse * scale) + ", \"mean\": " + Num(s.mean * scale) +
         ", \"max\": " + Num(s.max * scale) + ", \"std\": " + Num(s.std * scale) + "}";
}

inline std::string AteJson(const motion::AteResult& a) {
  return "{\"samples\": " + std::to_string(a.samples) + ", \"x_m\": " + StatsJson(a.x) +
         ", \"y_m\": " + StatsJson(a.y) + ", \"xy_m\": " + StatsJson(a.xy) +
         ", \"theta_deg\": " + StatsJson(a.theta, 180.0 / M_PI) +
         ", \"final_error\": {\"x_m\": " + Num(a.final_error.x) + ", \"y_m\": " + Num(a.final_error.y) +
         ", \"theta_deg\": " + Num(a.final_error.theta * 180.0 / M_PI) + "}, \"alignment\": " + PoseJson(a.alignment) +
         "}";
}

// {"aligned": …, "anchored": …, "unaligned": …}: an estimate's errors under each convention.
inline std::string TrajectoryErrorsJson(const motion::TrajectoryErrors& e) {
  return "{\"aligned\": " + AteJson(e.aligned) + ",\n    \"anchored\": " + AteJson(e.anchored) +
         ",\n    \"unaligned\": " + AteJson(e.unaligned) + "}";
}

// A TUM trajectory file (written whole or not at all): a comment line naming what it holds, then
// one line per pose, each composed onto `frame` (the identity: as given).
inline void WriteTum(const std::string& path, const std::string& what, const std::vector<motion::TimedPose>& poses,
                     const motion::Pose2D& frame = {}) {
  WriteFileAtomically(path, [&](std::ostream& o) {
    o << "# " << what << (what.empty() ? "" : ": ") << "t x y z qx qy qz qw\n";
    for (const motion::TimedPose& p : poses) {
      const motion::Pose2D w = frame.Compose(p.pose);
      o << TumLine(p.t_us * 1e-6, w.x, w.y, w.theta);
    }
  });
}

}  // namespace mbot::app
