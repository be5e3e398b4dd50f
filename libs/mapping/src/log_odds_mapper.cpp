#include "mbot/mapping/log_odds_mapper.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace mbot::mapping {

LogOddsMapper::LogOddsMapper(const MapperOptions& options) : options_(options) {
  if (!(options.resolution_m > 0) || !(options.width_m > 0) || !(options.height_m > 0)) {
    throw std::invalid_argument("mapper: resolution and extent must be positive");
  }
  const int w = static_cast<int>(std::ceil(options.width_m / options.resolution_m));
  const int h = static_cast<int>(std::ceil(options.height_m / options.resolution_m));
  map_ = OccupancyGrid(w, h, options.resolution_m, options.center_x_m - 0.5 * w * options.resolution_m,
                       options.center_y_m - 0.5 * h * options.resolution_m);
  ResetMoments();
}

void LogOddsMapper::ResetMoments() {
  if (!options_.hit_moments) return;
  const long long cells = static_cast<long long>(map_.width()) * map_.height();
  if (cells > HitMoments::kMaxCells) {
    throw std::invalid_argument("mapper: a grid of " + std::to_string(cells) +
                                " cells is too large to keep hit moments for (at most " +
                                std::to_string(HitMoments::kMaxCells) + ")");
  }
  moments_.Reset(map_);
}

void LogOddsMapper::Reset(OccupancyGrid map) {
  options_.resolution_m = map.resolution();
  map_ = std::move(map);
  ResetMoments();
}

bool LogOddsMapper::EnsureCovers(double min_x, double min_y, double max_x, double max_y) {
  const double res = map_.resolution();
  const double x0 = map_.origin_x(), y0 = map_.origin_y();
  const double x1 = x0 + map_.width() * res, y1 = y0 + map_.height() * res;
  if (min_x >= x0 && min_y >= y0 && max_x < x1 && max_y < y1) return true;
  // Grow by whole blocks (a multiple of the cell size) on each side that is short, in doubles
  // first: a corrupt range must not overflow the cell counts.
  const double block = std::max(1.0, std::round(options_.grow_block_m / res));
  auto cells_needed = [&](double shortfall) {
    if (shortfall <= 0) return 0.0;
    return std::ceil(std::ceil(shortfall / res) / block) * block;
  };
  const double grown_w = map_.width() + cells_needed(x0 - min_x) + cells_needed(max_x - x1 + res);
  const double grown_h = map_.height() + cells_needed(y0 - min_y) + cells_needed(max_y - y1 + res);
  const double cap = options_.hit_moments ? double(HitMoments::kMaxCells) : double(kMaxGridCells);
  if (grown_w * grown_h > cap) return false;
  const int left = static_cast<int>(cells_needed(x0 - min_x)), bottom = static_cast<int>(cells_needed(y0 - min_y));
  const int right = static_cast<int>(cells_needed(max_x - x1 + res));
  const int top = static_cast<int>(cells_needed(max_y - y1 + res));
  OccupancyGrid grown(map_.width() + left + right, map_.height() + bottom + top, res, x0 - left * res,
                      y0 - bottom * res);
  for (int y = 0; y < map_.height(); ++y) {
    std::copy_n(&map_.cells()[static_cast<size_t>(y) * map_.width()], map_.width(),
                &grown.cells()[static_cast<size_t>(y + bottom) * grown.width() + left]);
  }
  map_ = std::move(grown);
  if (options_.hit_moments) moments_.Grow(map_, left, bottom);
  ++grow_count_;
  return true;
}

namespace {

// Clips the segment (x0, y0)-(x1, y1) to the box (Liang–Barsky). False when none of it is inside.
bool ClipSegment(double* x0, double* y0, double* x1, double* y1, double bx0, double by0, double bx1, double by1) {
  const double dx = *x1 - *x0, dy = *y1 - *y0;
  double t0 = 0.0, t1 = 1.0;
  const double p[4] = {-dx, dx, -dy, dy};
  const double q[4] = {*x0 - bx0, bx1 - *x0, *y0 - by0, by1 - *y0};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0.0) {
      if (q[i] < 0.0) return false;
      continue;
    }
    const double t = q[i] / p[i];
    if (p[i] < 0.0) {
      t0 = std::max(t0, t);
    } else {
      t1 = std::min(t1, t);
    }
    if (t0 > t1) return false;
  }
  const double ox = *x0, oy = *y0;
  *x0 = ox + t0 * dx;
  *y0 = oy + t0 * dy;
  *x1 = ox + t1 * dx;
  *y1 = oy + t1 * dy;
  return true;
}

}  // namespace

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

double LogOddsMapper::HitWeight(double range_m) const {
  const double p = options_.hit_range_power;
  if (p == 0) return 1.0;
  const double r = std::max(0.1, range_m);
  return p == 2 ? r * r : std::pow(r, p);
}

bool LogOddsMapper::Insert(const std::vector<ScanRay>& rays, const motion::Pose2D& robot_pose) {
  if (rays.empty()) return true;
  if (!std::isfinite(robot_pose.x) || !std::isfinite(robot_pose.y) || !std::isfinite(robot_pose.theta)) {
    ++rejected_scans_;
    return false;
  }
  const double c = std::cos(robot_pose.theta), s = std::sin(robot_pose.theta);
  struct WorldRay {
    double ox, oy, ex, ey;
    bool hit;
    bool dropped = false;
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
    if (!std::isfinite(w.ox) || !std::isfinite(w.oy) || !std::isfinite(w.ex) || !std::isfinite(w.ey)) {
      w = WorldRay{robot_pose.x, robot_pose.y, robot_pose.x, robot_pose.y, false, true};
      continue;
    }
    min_x = std::min({min_x, w.ox, w.ex});
    max_x = std::max({max_x, w.ox, w.ex});
    min_y = std::min({min_y, w.oy, w.ey});
    max_y = std::max({max_y, w.oy, w.ey});
  }
  if (options_.grow && !EnsureCovers(min_x, min_y, max_x, max_y)) {
    ++rejected_scans_;
    return false;
  }
  // Rays reaching far beyond the grid are clipped to a box around it (a grid's size on each side),
  // so a corrupt range costs no more than a ray across the grid; nearer rays keep their own ends.
  const double res = map_.resolution();
  const double margin = std::max(map_.width(), map_.height()) * res;
  const double bx0 = map_.origin_x() - margin, by0 = map_.origin_y() - margin;
  const double bx1 = map_.origin_x() + map_.width() * res + margin;
  const double by1 = map_.origin_y() + map_.height() * res + margin;

  const int hit = options_.hit_odds, miss = options_.miss_odds;
  std::vector<int> xs, ys;
  for (WorldRay& w : world) {
    if (w.dropped) continue;
    if (w.ox < bx0 || w.ox > bx1 || w.ex < bx0 || w.ex > bx1 || w.oy < by0 || w.oy > by1 || w.ey < by0 || w.ey > by1) {
      const double ex = w.ex, ey = w.ey;
      if (!ClipSegment(&w.ox, &w.oy, &w.ex, &w.ey, bx0, by0, bx1, by1)) continue;
      if (w.ex != ex || w.ey != ey) w.hit = false;  // the end is beyond the box, never a cell of the grid
    }
    int cx0, cy0, cx1, cy1;
    map_.WorldToCell(w.ox, w.oy, &cx0, &cy0);
    map_.WorldToCell(w.ex, w.ey, &cx1, &cy1);
    BresenhamLine(cx0, cy0, cx1, cy1, &xs, &ys);
    const size_t n = xs.size();
    // Every cell before the end is free; the end cell is occupied on a hit and free otherwise.
    for (size_t k = 0; k < n; ++k) {
      if (!map_.IsInside(xs[k], ys[k])) continue;
      int8_t& cell = map_.at(xs[k], ys[k]);
      const bool end_hit = k + 1 == n && w.hit;
      const int v = end_hit ? std::min(127, cell + hit) : std::max(-127, cell - miss);
      cell = static_cast<int8_t>(v);
      if (end_hit && options_.hit_moments) {
        moments_.Add(map_, xs[k], ys[k], w.ex, w.ey, HitMoments::DirectionOf(std::atan2(w.ey - w.oy, w.ex - w.ox)),
                     HitWeight(std::hypot(w.ex - w.ox, w.ey - w.oy)));
      }
    }
  }
  return true;
}

}  // namespace mbot::mapping
