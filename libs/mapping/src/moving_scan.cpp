#include "mbot/mapping/moving_scan.hpp"

#include <algorithm>
#include <cmath>

namespace mbot::mapping {

std::vector<ScanRay> DeskewScan(const std::vector<float>& ranges, const std::vector<float>& angles,
                                const std::vector<float>& fractions, const motion::Pose2D& start_in_end,
                                const motion::Pose2D& sensor, double sensor_max_range_m, const ScanOptions& options) {
  double max_range = options.max_range_m > 0 ? options.max_range_m : sensor_max_range_m;
  if (options.max_range_m > 0 && sensor_max_range_m > 0) max_range = std::min(max_range, sensor_max_range_m);
  std::vector<ScanRay> rays;
  rays.reserve(ranges.size());
  const motion::Pose2D identity;
  const int n = static_cast<int>(ranges.size());
  // A beam with no return (IsNoReturn) clears no_return_clear_m, not the whole range: through a pane
  // it would wipe out the walls behind (Intel with a fifth of its walls made glass: 0.0186 m when
  // those beams clear nothing, 1.41 m when they clear 30 m).
  const auto no_return = [&](double r) { return IsNoReturn(r, sensor_max_range_m); };
  const auto valid = [&](int j) { return !no_return(ranges[j]) && ranges[j] >= options.min_range_m; };
  for (int i = 0; i < n; ++i) {
    double r = ranges[i];
    if (options.smooth_beams > 0 && valid(i)) {
      double sum = 0;
      int used = 0;
      for (int j = std::max(0, i - options.smooth_beams); j <= std::min(n - 1, i + options.smooth_beams); ++j) {
        if (valid(j) && std::abs(ranges[j] - ranges[i]) <= options.smooth_max_step_m) sum += ranges[j], ++used;
      }
      r = sum / used;
    }
    double length;
    bool hit;
    if (no_return(r)) {
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

namespace {

// The beams' angles sweep more than 1.5π: a full revolution of a spinning lidar.
bool CoversTurn(const std::vector<float>& angles) {
  if (angles.size() < 3) return false;
  double turned = 0;
  for (size_t i = 1; i < angles.size(); ++i) turned += std::abs(motion::WrapAngle(angles[i] - angles[i - 1]));
  return turned > 1.5 * M_PI;
}

}  // namespace

BeamTimes TimeBeams(BeamTiming timing, const std::vector<float>& angles, const std::vector<int64_t>& beam_times,
                    int64_t period) {
  BeamTimes out;
  const size_t n = angles.size();
  // Beam times are usable when they span between half and twice the scan period and run forward
  // (a corrupt time, or one on another clock, would place beams far from the scan). In doubles: a
  // corrupt int64 must not overflow the subtraction.
  bool beams_usable = beam_times.size() == n && n > 1 && period > 0;
  if (beams_usable) {
    const double span = double(beam_times.back()) - double(beam_times.front());
    beams_usable = span > period / 2.0 && span <= 2.0 * period;
    for (size_t i = 1; beams_usable && i < n; ++i) beams_usable = beam_times[i] >= beam_times[i - 1];
  }
  if (timing == BeamTiming::kBeams || (timing == BeamTiming::kAuto && beams_usable)) {
    if (!beams_usable) {
      out.beam_times_unusable = true;
      return out;
    }
    out.duration_us = beam_times.back() - beam_times.front();
    out.fractions.resize(n);
    for (size_t i = 0; i < n; ++i) {
      out.fractions[i] = static_cast<float>(double(beam_times[i] - beam_times.front()) / out.duration_us);
    }
  } else if (timing == BeamTiming::kSpread ||
             (timing == BeamTiming::kAuto && period > 0 && period < 1'000'000 && CoversTurn(angles))) {
    out.duration_us = period > 0 && period < 1'000'000 ? period : 0;
    out.fractions.resize(n);
    for (size_t i = 0; i < n; ++i) out.fractions[i] = n > 1 ? float(double(i) / (n - 1)) : 1.0f;
  }
  return out;
}

}  // namespace mbot::mapping
