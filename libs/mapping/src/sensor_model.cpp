#include "mbot/mapping/sensor_model.hpp"

#include <algorithm>
#include <cmath>

#include "mbot/mapping/distance_transform.hpp"

namespace mbot::mapping {

void SensorModel::SetMap(const OccupancyGrid& map) {
  width_ = map.width();
  height_ = map.height();
  resolution_ = map.resolution();
  origin_x_ = map.origin_x();
  origin_y_ = map.origin_y();
  const size_t n = static_cast<size_t>(width_) * height_;
  std::vector<uint8_t> obstacle(n);
  for (size_t i = 0; i < n; ++i) obstacle[i] = map.cells()[i] > options_.occupied_threshold;
  const std::vector<float> d2 = SquaredDistanceTransform(obstacle, width_, height_);
  const double res2 = resolution_ * resolution_;
  const double inlier2 = options_.inlier_distance_m * options_.inlier_distance_m / res2;
  inlier_.resize(n);
  for (size_t i = 0; i < n; ++i) inlier_[i] = d2[i] <= inlier2;
  if (options_.kind == SensorModelKind::kLikelihoodField) {
    const double inv2s2 = 1.0 / (2.0 * options_.sigma_m * options_.sigma_m);
    const double dmax2 = options_.max_distance_m * options_.max_distance_m;
    const double norm = std::log(1.0 + options_.random_weight);
    auto value = [&](double dist2_m) {
      return static_cast<float>(std::log(std::exp(-std::min(dist2_m, dmax2) * inv2s2) + options_.random_weight) - norm);
    };
    off_map_ = value(dmax2);
    const int pw = width_ + 2;
    padded_.assign(static_cast<size_t>(pw) * (height_ + 2), off_map_);
    for (int y = 0; y < height_; ++y) {
      float* row = &padded_[static_cast<size_t>(y + 1) * pw + 1];
      const float* d2_row = &d2[static_cast<size_t>(y) * width_];
      for (int x = 0; x < width_; ++x) row[x] = value(double(d2_row[x]) * res2);
    }
    table_.clear();
  } else {
    table_.resize(n);
    for (size_t i = 0; i < n; ++i) {
      const int odds = map.cells()[i];
      table_[i] = odds > options_.occupied_threshold ? static_cast<float>(odds * options_.odds_scale) : 0.0f;
    }
    padded_.clear();
    off_map_ = 0.0f;
  }
}

ScanPoints SensorModel::Prepare(const std::vector<ScanRay>& rays) const {
  ScanPoints pts;
  const int stride = std::max(1, options_.ray_stride);
  int k = 0;
  for (const ScanRay& r : rays) {
    if (!r.hit) continue;
    if (k++ % stride != 0) continue;
    const double dx = r.ex - r.ox, dy = r.ey - r.oy, len = std::hypot(dx, dy);
    pts.x.push_back(r.ex);
    pts.y.push_back(r.ey);
    pts.step_x.push_back(len > 0 ? static_cast<float>(dx / len * resolution_) : 0.0f);
    pts.step_y.push_back(len > 0 ? static_cast<float>(dy / len * resolution_) : 0.0f);
  }
  return pts;
}

double SensorModel::LogLikelihood(const motion::Pose2D& pose, const ScanPoints& scan) const {
  if (!has_map()) return 0.0;  // action-only: every pose weighs the same
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  const double inv_res = 1.0 / resolution_;
  const double bx = (pose.x - origin_x_) * inv_res, by = (pose.y - origin_y_) * inv_res;
  const size_t n = scan.size();
  auto lookup = [&](double gx, double gy, float* v) {
    const int cx = static_cast<int>(std::floor(gx)), cy = static_cast<int>(std::floor(gy));
    if (cx < 0 || cy < 0 || cx >= width_ || cy >= height_) {
      *v = off_map_;
      return;
    }
    *v = table_[static_cast<size_t>(cy) * width_ + cx];
  };
  double sum = 0.0;
  if (options_.kind == SensorModelKind::kLikelihoodField) {
    // Branch-free: float cell coordinates shifted by the one-cell border, truncated and clamped into
    // the padded table (anything off the map lands on the border's off-map value).
    const float fc = static_cast<float>(c * inv_res), fs = static_cast<float>(s * inv_res);
    const float fx = static_cast<float>(bx + 1.0), fy = static_cast<float>(by + 1.0);
    const int max_x = width_ + 1, max_y = height_ + 1, pw = width_ + 2;
    const float* xs = scan.x.data();
    const float* ys = scan.y.data();
    const float* table = padded_.data();
    float acc = 0.0f;
    for (size_t i = 0; i < n; ++i) {
      const float gx = fx + fc * xs[i] - fs * ys[i];
      const float gy = fy + fs * xs[i] + fc * ys[i];
      const int cx = std::min(max_x, std::max(0, static_cast<int>(std::max(gx, -1.0f))));
      const int cy = std::min(max_y, std::max(0, static_cast<int>(std::max(gy, -1.0f))));
      acc += table[cy * pw + cx];
    }
    sum = acc;
  } else {
    const double w = options_.neighbour_weight;
    for (size_t i = 0; i < n; ++i) {
      const double gx = bx + (c * scan.x[i] - s * scan.y[i]) * inv_res;
      const double gy = by + (s * scan.x[i] + c * scan.y[i]) * inv_res;
      float v;
      lookup(gx, gy, &v);
      if (v <= 0.0f) {
        const double sx = (c * scan.step_x[i] - s * scan.step_y[i]) * inv_res;
        const double sy = (s * scan.step_x[i] + c * scan.step_y[i]) * inv_res;
        float before, after;
        lookup(gx - sx, gy - sy, &before);
        lookup(gx + sx, gy + sy, &after);
        v = static_cast<float>(w * std::max(before, after));
      }
      sum += v;
    }
  }
  return options_.log_scale * sum;
}

double SensorModel::InlierFraction(const motion::Pose2D& pose, const ScanPoints& scan) const {
  if (scan.size() == 0 || !has_map()) return 0.0;
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  int inliers = 0;
  for (size_t i = 0; i < scan.size(); ++i) {
    const double x = pose.x + c * scan.x[i] - s * scan.y[i], y = pose.y + s * scan.x[i] + c * scan.y[i];
    const int cx = static_cast<int>(std::floor((x - origin_x_) / resolution_));
    const int cy = static_cast<int>(std::floor((y - origin_y_) / resolution_));
    if (cx >= 0 && cy >= 0 && cx < width_ && cy < height_ && inlier_[static_cast<size_t>(cy) * width_ + cx]) ++inliers;
  }
  return double(inliers) / scan.size();
}

}  // namespace mbot::mapping
