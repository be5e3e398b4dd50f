#include "mbot/planning/obstacle_distance_grid.hpp"

#include <algorithm>
#include <cmath>

namespace mbot::planning {

using mapping::CellRect;
using mapping::EuclideanDistanceTransform;

ObstacleDistanceGrid::ObstacleDistanceGrid(const mapping::OccupancyGrid& map, const ObstacleDistanceOptions& options)
    : options_(options) {
  Recompute(map);
}

// The obstacle mask and, with a separate unknown margin, the unknown mask (else left empty).
void ObstacleDistanceGrid::Masks(const mapping::OccupancyGrid& map) {
  std::vector<uint8_t>* obstacle = &obstacle_mask_;
  std::vector<uint8_t>* unknown = &unknown_mask_;
  const int threshold = options_.occupied_threshold;
  const int free_at = std::min(options_.free_threshold, threshold);
  const int8_t* cells = map.cells().data();
  const size_t n = map.cells().size();
  obstacle->resize(n);
  uint8_t* o = obstacle->data();
  // One comparison per cell in each case, so the loops vectorise: unknown cells are those above
  // free_at and at most threshold.
  if (SeparateUnknown()) {
    unknown->resize(n);
    uint8_t* u = unknown->data();
    for (size_t i = 0; i < n; ++i) {
      o[i] = cells[i] > threshold;
      u[i] = cells[i] > free_at && cells[i] <= threshold;
    }
  } else {
    const int blocked_above = options_.unknown_is_obstacle ? free_at : threshold;
#pragma omp parallel for schedule(static) if (n > 100000)
    for (size_t i = 0; i < n; ++i) o[i] = cells[i] > blocked_above;
  }
}

// Metres from the squared cell distances over `rect`. Unknown space (with a margin) counts as an
// obstacle unknown_margin_m farther than it is; an unknown cell itself stays at 0, so it is never
// entered whatever the margin.
void ObstacleDistanceGrid::Distances(const CellRect& rect) {
  const float res = static_cast<float>(resolution_);
  const float margin = static_cast<float>(options_.unknown_margin_m);
  const bool separate = SeparateUnknown();
  // Branch-free so it vectorises: sqrt of the no-obstacle sentinel is replaced afterwards.
  auto metres_row = [&](const int32_t* sq, float* out, float add) {
    for (int x = rect.x0; x <= rect.x1; ++x) {
      const float m = std::sqrt(static_cast<float>(sq[x])) * res + add;
      out[x] = sq[x] == EuclideanDistanceTransform::kNoObstacle ? kInfinity : m;
    }
  };
  const size_t cells = static_cast<size_t>(rect.x1 - rect.x0 + 1) * (rect.y1 - rect.y0 + 1);
#pragma omp parallel if (cells > 100000)
  {
    std::vector<float> scratch(separate ? width_ : 0);
#pragma omp for schedule(static)
    for (int y = rect.y0; y <= rect.y1; ++y) {
      const size_t row = static_cast<size_t>(y) * width_;
      float* out = &dist_[row];
      metres_row(&obstacles_.squared()[row], out, 0.0f);
      if (!separate) continue;
      const int32_t* unknown = &unknown_.squared()[row];
      metres_row(unknown, scratch.data(), margin);
      for (int x = rect.x0; x <= rect.x1; ++x) out[x] = unknown[x] == 0 ? 0.0f : std::min(out[x], scratch[x]);
    }
  }
}

void ObstacleDistanceGrid::Recompute(const mapping::OccupancyGrid& map) {
  width_ = map.width();
  height_ = map.height();
  resolution_ = map.resolution();
  origin_x_ = map.origin_x();
  origin_y_ = map.origin_y();
  Masks(map);
  obstacles_.Compute(obstacle_mask_.data(), width_, height_);
  if (SeparateUnknown()) unknown_.Compute(unknown_mask_.data(), width_, height_);
  dist_.resize(static_cast<size_t>(width_) * height_);
  if (!dist_.empty()) Distances({0, 0, width_ - 1, height_ - 1});
}

CellRect ObstacleDistanceGrid::Update(const mapping::OccupancyGrid& map) {
  const bool same_frame = map.width() == width_ && map.height() == height_ && map.resolution() == resolution_ &&
                          map.origin_x() == origin_x_ && map.origin_y() == origin_y_ && !dist_.empty();
  if (!same_frame) {
    Recompute(map);
    return dist_.empty() ? CellRect{} : CellRect{0, 0, width_ - 1, height_ - 1};
  }
  Masks(map);
  CellRect changed = obstacles_.Update(obstacle_mask_.data(), width_, height_);
  if (SeparateUnknown()) changed.Add(unknown_.Update(unknown_mask_.data(), width_, height_));
  if (!changed.empty()) Distances(changed);
  return changed;
}

void ObstacleDistanceGrid::WorldToCell(double x, double y, int* cx, int* cy) const {
  *cx = static_cast<int>(std::floor((x - origin_x_) / resolution_));
  *cy = static_cast<int>(std::floor((y - origin_y_) / resolution_));
}

void ObstacleDistanceGrid::CellToWorld(int cx, int cy, double* x, double* y) const {
  *x = origin_x_ + (cx + 0.5) * resolution_;
  *y = origin_y_ + (cy + 0.5) * resolution_;
}

}  // namespace mbot::planning
