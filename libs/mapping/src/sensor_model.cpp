#include "mbot/mapping/sensor_model.hpp"

#include <algorithm>
#include <cmath>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "mbot/mapping/distance_transform.hpp"

namespace mbot::mapping {

void SensorModel::SetMap(const OccupancyGrid& map) {
  const bool same_geometry = width_ == map.width() && height_ == map.height() && resolution_ == map.resolution() &&
                             origin_x_ == map.origin_x() && origin_y_ == map.origin_y();
  width_ = map.width();
  height_ = map.height();
  resolution_ = map.resolution();
  origin_x_ = map.origin_x();
  origin_y_ = map.origin_y();
  const size_t n = static_cast<size_t>(width_) * height_;
  if (options_.kind == SensorModelKind::kSimplifiedField) {
    table_.resize(n);
    for (size_t i = 0; i < n; ++i) {
      const int odds = map.cells()[i];
      table_[i] = odds > options_.occupied_threshold ? static_cast<float>(odds * options_.odds_scale) : 0.0f;
    }
    padded_.clear();
    off_map_ = 0.0f;
  }
  // The distance tables depend only on which cells are obstacles. With the same geometry, only
  // the cells near an obstacle that appeared or vanished can change, and only if one did.
  std::vector<uint8_t> obstacle(n);
  for (size_t i = 0; i < n; ++i) obstacle[i] = map.cells()[i] > options_.occupied_threshold;
  if (!same_geometry || obstacle_.size() != n) {
    obstacle_ = std::move(obstacle);
    BuildLookup();
    if (options_.kind == SensorModelKind::kLikelihoodField) {
      padded_.assign(static_cast<size_t>(width_ + 2) * (height_ + 2), off_map_);
      table_.clear();
    }
    inlier_.assign(n, 0);
    UpdateDistances(0, 0, width_ - 1, height_ - 1);
    return;
  }
  int x0 = width_, y0 = height_, x1 = -1, y1 = -1;
  for (int y = 0; y < height_; ++y) {
    const size_t row = static_cast<size_t>(y) * width_;
    for (int x = 0; x < width_; ++x) {
      if (obstacle[row + x] != obstacle_[row + x]) {
        x0 = std::min(x0, x), x1 = std::max(x1, x);
        y0 = std::min(y0, y), y1 = std::max(y1, y);
      }
    }
  }
  obstacle_ = std::move(obstacle);
  if (x1 < 0) return;  // no obstacle changed
  UpdateDistances(x0 - reach_cells_, y0 - reach_cells_, x1 + reach_cells_, y1 + reach_cells_);
}

void SensorModel::BuildLookup() {
  // Exact squared distances between cells are integers; every one beyond the reach of the
  // likelihood field and the inlier test scores as far away.
  const double res2 = resolution_ * resolution_;
  const double reach_m = std::max(options_.max_distance_m, options_.inlier_distance_m);
  reach_cells_ = static_cast<int>(std::ceil(reach_m / resolution_)) + 1;
  const double inv2s2 = 1.0 / (2.0 * options_.sigma_m * options_.sigma_m);
  const double dmax2 = options_.max_distance_m * options_.max_distance_m;
  const double norm = std::log(1.0 + options_.random_weight);
  auto value = [&](double dist2_m) {
    return static_cast<float>(std::log(std::exp(-std::min(dist2_m, dmax2) * inv2s2) + options_.random_weight) - norm);
  };
  off_map_ = options_.kind == SensorModelKind::kLikelihoodField ? value(dmax2) : 0.0f;
  const int max_d2 = reach_cells_ * reach_cells_;
  field_lut_.resize(max_d2 + 1);
  inlier_lut_.resize(max_d2 + 1);
  const double inlier2 = options_.inlier_distance_m * options_.inlier_distance_m;
  for (int d2 = 0; d2 <= max_d2; ++d2) {
    field_lut_[d2] = value(d2 * res2);
    inlier_lut_[d2] = d2 * res2 <= inlier2 + 1e-12;
  }
}

void SensorModel::UpdateDistances(int x0, int y0, int x1, int y1) {
  // Cells of [x0, x1] × [y0, y1] get their distance to the nearest obstacle within reach; those
  // obstacles lie inside the box grown by the reach, so the transform runs on that window only.
  x0 = std::max(0, x0), y0 = std::max(0, y0);
  x1 = std::min(width_ - 1, x1), y1 = std::min(height_ - 1, y1);
  const int wx0 = std::max(0, x0 - reach_cells_), wy0 = std::max(0, y0 - reach_cells_);
  const int wx1 = std::min(width_ - 1, x1 + reach_cells_), wy1 = std::min(height_ - 1, y1 + reach_cells_);
  const int ww = wx1 - wx0 + 1, wh = wy1 - wy0 + 1;
  std::vector<uint8_t> window(static_cast<size_t>(ww) * wh);
  for (int y = 0; y < wh; ++y) {
    std::copy_n(&obstacle_[static_cast<size_t>(wy0 + y) * width_ + wx0], ww, &window[static_cast<size_t>(y) * ww]);
  }
  const std::vector<float> d2 = SquaredDistanceTransform(window, ww, wh);
  const int max_d2 = static_cast<int>(field_lut_.size()) - 1;
  const bool field = options_.kind == SensorModelKind::kLikelihoodField;
  const int pw = width_ + 2;
  for (int y = y0; y <= y1; ++y) {
    const float* d2_row = &d2[static_cast<size_t>(y - wy0) * ww];  // window column x - wx0
    float* padded_row = field ? &padded_[static_cast<size_t>(y + 1) * pw + 1] : nullptr;
    uint8_t* inlier_row = &inlier_[static_cast<size_t>(y) * width_];
    for (int x = x0; x <= x1; ++x) {
      const float w = d2_row[x - wx0];
      const int k = w <= max_d2 ? static_cast<int>(w) : max_d2;
      if (field) padded_row[x] = field_lut_[k];
      inlier_row[x] = inlier_lut_[k];
    }
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

namespace {

// One pose's likelihood-field lookup: float cell coordinates shifted by the table's one-cell border,
// clamped into the padded table (anything off the map lands on the border's off-map value) and
// truncated.
struct FieldPose {
  float fx, fy, fc, fs, max_x, max_y;
  int pw;
  int Cell(float x, float y) const {
    const float gx = std::min(max_x, std::max(0.0f, fx + fc * x - fs * y));
    const float gy = std::min(max_y, std::max(0.0f, fy + fs * x + fc * y));
    return static_cast<int>(gy) * pw + static_cast<int>(gx);
  }
};

constexpr int kLanes = 8;

// The lanes' sums, added in a fixed order.
float LaneTotal(const float* acc) {
  return ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7]));
}

// Branch-free, eight beams at a time: their cells are worked out together (the loop vectorises),
// then summed into eight running sums (beam i into lane i mod 8), so no addition waits for the one
// before it.
float FieldSum(const FieldPose& p, const float* xs, const float* ys, size_t n, const float* table) {
  float acc[kLanes] = {};
  int32_t idx[kLanes];
  size_t i = 0;
  for (; i + kLanes <= n; i += kLanes) {
    for (int k = 0; k < kLanes; ++k) idx[k] = p.Cell(xs[i + k], ys[i + k]);
    for (int k = 0; k < kLanes; ++k) acc[k] += table[idx[k]];
  }
  for (int k = 0; i < n; ++i, ++k) acc[k] += table[p.Cell(xs[i], ys[i])];
  return LaneTotal(acc);
}

#if defined(__x86_64__)
// The same sums with AVX2: eight cells per instruction and one gather. The operations and their
// order are FieldSum's (no fused multiply-add: the file is built with -ffp-contract=off).
__attribute__((target("avx2"))) float FieldSumAvx2(const FieldPose& p, const float* xs, const float* ys, size_t n,
                                                   const float* table) {
  const __m256 fx = _mm256_set1_ps(p.fx), fy = _mm256_set1_ps(p.fy);
  const __m256 fc = _mm256_set1_ps(p.fc), fs = _mm256_set1_ps(p.fs);
  const __m256 max_x = _mm256_set1_ps(p.max_x), max_y = _mm256_set1_ps(p.max_y), zero = _mm256_setzero_ps();
  const __m256i pw = _mm256_set1_epi32(p.pw);
  __m256 acc = _mm256_setzero_ps();
  size_t i = 0;
  for (; i + kLanes <= n; i += kLanes) {
    const __m256 x = _mm256_loadu_ps(xs + i), y = _mm256_loadu_ps(ys + i);
    __m256 gx = _mm256_sub_ps(_mm256_add_ps(fx, _mm256_mul_ps(fc, x)), _mm256_mul_ps(fs, y));
    __m256 gy = _mm256_add_ps(_mm256_add_ps(fy, _mm256_mul_ps(fs, x)), _mm256_mul_ps(fc, y));
    gx = _mm256_min_ps(_mm256_max_ps(gx, zero), max_x);  // maxps(v, 0) is 0 for a NaN, as std::max(0, v)
    gy = _mm256_min_ps(_mm256_max_ps(gy, zero), max_y);
    const __m256i idx = _mm256_add_epi32(_mm256_mullo_epi32(_mm256_cvttps_epi32(gy), pw), _mm256_cvttps_epi32(gx));
    acc = _mm256_add_ps(acc, _mm256_i32gather_ps(table, idx, 4));
  }
  alignas(32) float lanes[kLanes];
  _mm256_store_ps(lanes, acc);
  for (int k = 0; i < n; ++i, ++k) lanes[k] += table[p.Cell(xs[i], ys[i])];
  return LaneTotal(lanes);
}
#endif

}  // namespace

bool SensorModel::SimdAvailable() {
#if defined(__x86_64__)
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return avx2;
#else
  return false;
#endif
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
    const FieldPose p{static_cast<float>(bx + 1.0),
                      static_cast<float>(by + 1.0),
                      static_cast<float>(c * inv_res),
                      static_cast<float>(s * inv_res),
                      static_cast<float>(width_ + 1),
                      static_cast<float>(height_ + 1),
                      width_ + 2};
#if defined(__x86_64__)
    if (use_simd_) {
      sum = FieldSumAvx2(p, scan.x.data(), scan.y.data(), n, padded_.data());
    } else {
      sum = FieldSum(p, scan.x.data(), scan.y.data(), n, padded_.data());
    }
#else
    sum = FieldSum(p, scan.x.data(), scan.y.data(), n, padded_.data());
#endif
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
