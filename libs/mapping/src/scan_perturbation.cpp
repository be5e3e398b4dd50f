#include "mbot/mapping/scan_perturbation.hpp"

#include <cmath>
#include <limits>

#include "mbot/mapping/moving_scan.hpp"

namespace mbot::mapping {

namespace {

// A well-mixed 64-bit hash (splitmix64's finaliser).
uint64_t Mix(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

constexpr double kGlassPatchM = 1.0;
constexpr double kPersonRadiusM = 0.2, kPersonSpeedMS = 1.0;
constexpr double kNearestPersonM = 0.8, kFarthestPersonM = 4.0;  // where a person starts, from the sensor
constexpr double kShortestWalkS = 2.0, kLongestWalkS = 6.0;

}  // namespace

ScanPerturbation::ScanPerturbation(const ScanPerturbationOptions& options, uint64_t seed)
    : o_(options), seed_(Mix(seed ^ 0x676c617373ULL)), rng_(seed ^ 0x70656f706c65ULL), people_(options.people) {}

bool ScanPerturbation::Glass(double x, double y) const {
  const auto cx = static_cast<int64_t>(std::floor(x / kGlassPatchM));
  const auto cy = static_cast<int64_t>(std::floor(y / kGlassPatchM));
  const uint64_t h = Mix(seed_ ^ Mix(static_cast<uint64_t>(cx) * 0x9e3779b97f4a7c15ULL + static_cast<uint64_t>(cy)));
  return static_cast<double>(h >> 11) * 0x1.0p-53 < o_.glass_share;
}

void ScanPerturbation::Place(Person* p, int64_t t_us, const motion::Pose2D& sensor) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double d = kNearestPersonM + (kFarthestPersonM - kNearestPersonM) * u(rng_), bearing = 2 * M_PI * u(rng_);
  const double heading = 2 * M_PI * u(rng_);
  p->x = sensor.x + d * std::cos(bearing);
  p->y = sensor.y + d * std::sin(bearing);
  p->vx = kPersonSpeedMS * std::cos(heading);
  p->vy = kPersonSpeedMS * std::sin(heading);
  p->until_us = t_us + static_cast<int64_t>((kShortestWalkS + (kLongestWalkS - kShortestWalkS) * u(rng_)) * 1e6);
}

void ScanPerturbation::Apply(int64_t t_us, const motion::Pose2D& sensor, const std::vector<float>& angles,
                             double max_range_m, std::vector<float>* ranges) {
  const double dt = last_us_ >= 0 && t_us > last_us_ ? (t_us - last_us_) * 1e-6 : 0.0;
  last_us_ = t_us;
  const double r2 = kPersonRadiusM * kPersonRadiusM;
  for (Person& p : people_) {
    p.x += p.vx * dt, p.y += p.vy * dt;
    const double dx = p.x - sensor.x, dy = p.y - sensor.y;
    // A person who walked off, too far or onto the sensor is replaced by another.
    if (p.until_us < 0 || t_us >= p.until_us || dx * dx + dy * dy > 4 * kFarthestPersonM * kFarthestPersonM ||
        dx * dx + dy * dy <= r2) {
      Place(&p, t_us, sensor);
    }
  }
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const size_t n = std::min(angles.size(), ranges->size());
  for (size_t i = 0; i < n; ++i) {
    float& range = (*ranges)[i];
    const double a = sensor.theta + angles[i], c = std::cos(a), s = std::sin(a);
    if (o_.glass_share > 0 && !IsNoReturn(range, max_range_m) && Glass(sensor.x + range * c, sensor.y + range * s)) {
      ++glass_beams_;
      if (u(rng_) < 0.5) {
        range = max_range_m > 0 ? static_cast<float>(max_range_m) : std::numeric_limits<float>::quiet_NaN();
      } else {
        const double behind = range * (1.5 + 1.5 * u(rng_));
        range = max_range_m > 0 && behind >= max_range_m ? static_cast<float>(max_range_m) : static_cast<float>(behind);
      }
    }
    // The nearest person along the beam, in front of whatever it returned from.
    double nearest = std::numeric_limits<double>::infinity();
    for (const Person& p : people_) {
      const double px = p.x - sensor.x, py = p.y - sensor.y;
      const double along = px * c + py * s;
      if (along <= 0) continue;
      const double across2 = px * px + py * py - along * along;
      if (across2 >= r2) continue;
      nearest = std::min(nearest, along - std::sqrt(r2 - across2));
    }
    if (std::isfinite(nearest) && (IsNoReturn(range, max_range_m) || nearest < range)) {
      range = static_cast<float>(nearest);
      ++person_beams_;
    }
  }
}

}  // namespace mbot::mapping
