#include "mbot/reports/json.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/strings.hpp"

namespace mbot::reports {

Json Number(double v, int significant) {
  if (!std::isfinite(v)) return nullptr;
  return std::stod(Significant(v, significant));
}

std::string Num(double v, int significant) { return std::isfinite(v) ? Significant(v, significant) : "null"; }

Json PoseJson(const motion::Pose2D& p) { return {{"x", Number(p.x)}, {"y", Number(p.y)}, {"theta", Number(p.theta)}}; }

Json StatsJson(const motion::ErrorStats& s, double scale) {
  return {{"rmse", Number(s.rmse * scale)},
          {"mean", Number(s.mean * scale)},
          {"max", Number(s.max * scale)},
          {"std", Number(s.std * scale)}};
}

Json AteJson(const motion::AteResult& a) {
  Json j;
  j["samples"] = a.samples;
  j["x_m"] = StatsJson(a.x);
  j["y_m"] = StatsJson(a.y);
  j["xy_m"] = StatsJson(a.xy);
  j["theta_deg"] = StatsJson(a.theta, 180.0 / M_PI);
  j["final_error"] = {{"x_m", Number(a.final_error.x)},
                      {"y_m", Number(a.final_error.y)},
                      {"theta_deg", Number(a.final_error.theta * 180.0 / M_PI)}};
  j["alignment"] = PoseJson(a.alignment);
  return j;
}

Json TrajectoryErrorsJson(const motion::TrajectoryErrors& e) {
  return {{"aligned", AteJson(e.aligned)}, {"anchored", AteJson(e.anchored)}, {"unaligned", AteJson(e.unaligned)}};
}

double Median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

SampleStats SampleStats::Of(const std::vector<double>& v) {
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

Json SampleStats::ToJson() const {
  return {{"count", count},           {"min", Number(min)}, {"mean", Number(mean)},
          {"median", Number(median)}, {"max", Number(max)}, {"std", Number(std)}};
}

void WriteJson(const std::string& path, const Json& j) {
  WriteFileAtomically(path, [&](std::ostream& out) { out << j.dump(2) << "\n"; });
}

Json ReadJson(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot be read");
  try {
    return Json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(path + ": not valid JSON (" + e.what() + ")");
  }
}

}  // namespace mbot::reports
