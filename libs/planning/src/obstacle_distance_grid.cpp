#include "mbot/planning/obstacle_distance_grid.hpp"

#include <algorithm>
#include <cmath>

#include "mbot/mapping/distance_transform.hpp"

namespace mbot::planning {

using mapping::SquaredDistanceTransform;

ObstacleDistanceGrid::ObstacleDistanceGrid(const mapping::OccupancyGrid& map, const ObstacleDistanceOptions& options)
    : width_(map.width()),
      height_(map.height()),
      resolution_(map.resolution()),
      origin_x_(map.origin_x()),
      origin_y_(map.origin_y()) {
  std::vector<uint8_t> obstacle(map.cells().size());
  const int threshold = options.occupied_threshold;
  const bool separate_unknown = options.unknown_is_obstacle && options.unknown_margin_m > 0;
  const int free_at = std::min(options.free_threshold, threshold);
  auto is_unknown = [&](int c) { return c > free_at && c <= threshold; };
  for (size_t i = 0; i < obstacle.size(); ++i) {
    const int c = map.cells()[i];
    obstacle[i] = c > threshold || (options.unknown_is_obstacle && !separate_unknown && is_unknown(c));
  }
  dist_ = SquaredDistanceTransform(obstacle, width_, height_);
  const float res = static_cast<float>(resolution_);
  for (float& v : dist_) v = std::sqrt(v) * res;  // sqrt(inf) = inf
  if (!separate_unknown) return;
  // Unknown space counts as an obstacle unknown_margin_m farther than it is; an unknown cell itself
  // stays at 0, so it is never entered whatever the margin.
  for (size_t i = 0; i < obstacle.size(); ++i) obstacle[i] = is_unknown(map.cells()[i]);
  const std::vector<float> unknown = SquaredDistanceTransform(obstacle, width_, height_);
  const float margin = static_cast<float>(options.unknown_margin_m);
  for (size_t i = 0; i < dist_.size(); ++i) {
    dist_[i] = obstacle[i] ? 0.0f : std::min(dist_[i], std::sqrt(unknown[i]) * res + margin);
  }
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
