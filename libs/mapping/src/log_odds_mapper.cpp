#include "mbot/mapping/log_odds_mapper.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mbot::mapping {

LogOddsMapper::LogOddsMapper(const MapperOptions& options) : options_(options) {
  if (!(options.resolution_m > 0) || !(options.width_m > 0) || !(options.height_m > 0)) {
    throw std::invalid_argument("mapper: resolution and extent must be positive");
  }
  const int w = static_cast<int>(std::ceil(options.width_m / options.resolution_m));
  const int h = static_cast<int>(std::ceil(options.height_m / options.resolution_m));
  map_ = OccupancyGrid(w, h, options.resolution_m, options.center_x_m - 0.5 * w * options.resolution_m,
                       options.center_y_m - 0.5 * h * options.resolution_m);
}

void LogOddsMapper::Reset(OccupancyGrid map) {
  options_.resolution_m = map.resolution();
  map_ = std::move(map);
}

void LogOddsMapper::EnsureCovers(double min_x, double min_y, double max_x, double max_y) {
  const double res = map_.resolution();
  const double x0 = map_.origin_x(), y0 = map_.origin_y();
  const double x1 = x0 + map_.width() * res, y1 = y0 + map_.height() * res;
  if (min_x >= x0 && min_y >= y0 && max_x < x1 && max_y < y1) return;
  // Grow by whole blocks (a multiple of the cell size) on each side that is short.
  const int block = std::max(1, static_cast<int>(std::lround(options_.grow_block_m / res)));
  auto cells_needed = [&](double shortfall) {
    if (shortfall <= 0) return 0;
    const int cells = static_cast<int>(std::ceil(shortfall / res));
    return (cells + block - 1) / block * block;
  };
  const int left = cells_needed(x0 - min_x), bottom = cells_needed(y0 - min_y);
  const int right = cells_needed(max_x - x1 + res), top = cells_needed(max_y - y1 + res);
  OccupancyGrid grown(map_.width() + left + right, map_.height() + bottom + top, res, x0 - left * res,
                      y0 - bottom * res);
  for (int y = 0; y < map_.height(); ++y) {
    std::copy_n(&map_.cells()[static_cast<size_t>(y) * map_.width()], map_.width(),
                &grown.cells()[static_cast<size_t>(y + bottom) * grown.width() + left]);
  }
  map_ = std::move(grown);
  ++grow_count_;
}

void BresenhamLine(int x0, int y0, int x1, int y1, std::vector<int>* xs, std::vector<int>* ys) {
  xs->clear();
  ys->clear();
  const int dx = std::abs(x1 - x0), dy = -std::abs(y1 - y0);
  const int sx = x0 < x1 ? 1 : -1, sy = y0 < y1 ? 1 : -1;
  int err = dx + dy;
  while (true) {
    xs->push_back(x0);
    ys->push_back(y0);
    if (x0 == x1 && y0 == y1) break;
    const int e2 = 2 * err;
    if (e2 >= dy) {
      err += dy;
      x0 += sx;
    }
    if (e2 <= dx) {
      err += dx;
      y0 += sy;
    }
  }
}

void LogOddsMapper::Insert(const std::vector<ScanRay>& rays, const motion::Pose2D& robot_pose) {
  if (rays.empty()) return;
  const double c = std::cos(robot_pose.theta), s = std::sin(robot_pose.theta);
  struct WorldRay {
    double ox, oy, ex, ey;
    bool hit;
  };
  std::vector<WorldRay> world(rays.size());
  double min_x = robot_pose.x, max_x = robot_pose.x, min_y = robot_pose.y, max_y = robot_pose.y;
  for (size_t i = 0; i < rays.size(); ++i) {
    const ScanRay& r = rays[i];
    WorldRay& w = world[i];
    w.ox = robot_pose.x + c * r.ox - s * r.oy;
    w.oy = robot_pose.y + s * r.ox + c * r.oy;
    w.ex = robot_pose.x + c * r.ex - s * r.ey;
    w.ey = robot_pose.y + s * r.ex + c * r.ey;
    w.hit = r.hit;
    min_x = std::min({min_x, w.ox, w.ex});
    max_x = std::max({max_x, w.ox, w.ex});
    min_y = std::min({min_y, w.oy, w.ey});
    max_y = std::max({max_y, w.oy, w.ey});
  }
  if (options_.grow) EnsureCovers(min_x, min_y, max_x, max_y);

  const int hit = options_.hit_odds, miss = options_.miss_odds;
  std::vector<int> xs, ys;
  for (const WorldRay& w : world) {
    int cx0, cy0, cx1, cy1;
    map_.WorldToCell(w.ox, w.oy, &cx0, &cy0);
    map_.WorldToCell(w.ex, w.ey, &cx1, &cy1);
    BresenhamLine(cx0, cy0, cx1, cy1, &xs, &ys);
    const size_t n = xs.size();
    // Every cell before the end is free; the end cell is occupied on a hit and free otherwise.
    for (size_t k = 0; k < n; ++k) {
      if (!map_.IsInside(xs[k], ys[k])) continue;
      int8_t& cell = map_.at(xs[k], ys[k]);
      const int v = (k + 1 == n && w.hit) ? std::min(127, cell + hit) : std::max(-127, cell - miss);
      cell = static_cast<int8_t>(v);
    }
  }
}

}  // namespace mbot::mapping
