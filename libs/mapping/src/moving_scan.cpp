#include "mbot/mapping/moving_scan.hpp"

#include <cmath>

namespace mbot::mapping {

std::vector<ScanRay> DeskewScan(const std::vector<float>& ranges, const std::vector<float>& angles,
                                const std::vector<float>& fractions, const motion::Pose2D& start_in_end,
                                const motion::Pose2D& sensor, double sensor_max_range_m,
                                const ScanOptions& options) {
  double max_range = options.max_range_m > 0 ? options.max_range_m : sensor_max_range_m;
  if (options.max_range_m > 0 && sensor_max_range_m > 0) max_range = std::min(max_range, sensor_max_range_m);
  std::vector<ScanRay> rays;
  rays.reserve(ranges.size());
  const motion::Pose2D identity;
  for (size_t i = 0; i < ranges.size(); ++i) {
    const double r = ranges[i];
    double length;
    bool hit;
    if (!std::isfinite(r) || r <= 0.0) {  // no return
      if (options.no_return_clear_m <= 0) continue;
      length = options.no_return_clear_m;
      hit = false;
    } else if (r < options.min_range_m) {
      continue;
    } else if (max_range > 0 && r >= max_range) {
      length = max_range;
      hit = false;
    } else {
      length = r;
      hit = true;
    }
    const double f = fractions.empty() ? 1.0 : fractions[i];
    const motion::Pose2D p = motion::Interpolate(start_in_end, identity, f).Compose(sensor);
    const double a = p.theta + angles[i];
    ScanRay ray;
    ray.ox = static_cast<float>(p.x);
    ray.oy = static_cast<float>(p.y);
    ray.ex = static_cast<float>(p.x + length * std::cos(a));
    ray.ey = static_cast<float>(p.y + length * std::sin(a));
    ray.hit = hit;
    rays.push_back(ray);
  }
  return rays;
}

}  // namespace mbot::mapping
