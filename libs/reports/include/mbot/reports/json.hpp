// The JSON every report is written in, through nlohmann-json (Debian's nlohmann-json3-dev): keys in
// the order a report adds them, numbers to 6 significant digits (non-finite: null), written whole or
// not at all, and read back the same way (tests, merges).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mbot/motion/pose2d.hpp"
#include "mbot/motion/trajectory_error.hpp"

namespace mbot::reports {

using Json = nlohmann::ordered_json;

// A number as the reports give it: `significant` digits, null when it is not finite.
Json Number(double v, int significant = 6);
// The same number as text, for printed lines and tables ("null" when it is not finite).
std::string Num(double v, int significant = 6);
// {"x": …, "y": …, "theta": …}
Json PoseJson(const motion::Pose2D& p);
// {"rmse": …, "mean": …, "max": …, "std": …}, scaled (radians → degrees).
Json StatsJson(const motion::ErrorStats& s, double scale = 1.0);
// An estimate's errors against the truth: samples, per axis, the final error, the alignment.
Json AteJson(const motion::AteResult& a);
// {"aligned": …, "anchored": …, "unaligned": …}
Json TrajectoryErrorsJson(const motion::TrajectoryErrors& e);

// min / mean / median / max / std of a sample, the form the botlab reports print their timings in.
struct SampleStats {
  size_t count = 0;
  double min = NAN, mean = NAN, median = NAN, max = NAN, std = NAN;
  static SampleStats Of(const std::vector<double>& v);
  Json ToJson() const;  // {"count": …, "min": …, "mean": …, "median": …, "max": …, "std": …}
};

// The median of `v` (the upper one of an even count); NaN when empty.
double Median(std::vector<double> v);

// Writes `j` to `path` (2-space indentation, a newline at the end) through a temporary file.
void WriteJson(const std::string& path, const Json& j);
// Reads a JSON file; throws std::runtime_error naming the path and what is wrong.
Json ReadJson(const std::string& path);

}  // namespace mbot::reports
