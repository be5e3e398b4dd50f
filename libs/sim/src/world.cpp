#include "mbot/sim/world.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>

#include "mbot/common/strings.hpp"
#include "mbot/drivers/map_io.hpp"
#include "world_limits.hpp"

namespace mbot::sim {
namespace fs = std::filesystem;

namespace {

using namespace world_limits;

}  // namespace

struct WorldIndex {
  // Arena world: walls as capsules of radius h, and a uniform bucket grid over the true map's
  // extent listing, per bucket, the walls whose thickened bounding box overlaps it (CSR layout).
  std::vector<Capsule> capsules;
  double h = 0;
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // extent of the true map = of the bucket grid
  double bucket = kBucketSize;
  int nbx = 0, nby = 0;
  std::vector<int> bucket_start;  // nbx * nby + 1 offsets into bucket_items
  std::vector<int> bucket_items;

  // Grid world: the Euclidean distance from each cell's centre to the nearest wall cell's centre
  // [cells] (a lower bound that lets ClearanceAt skip the empty rings around a point).
  std::vector<float> centre_distance;
  bool any_wall_cell = false;

  int BucketIndex(int bx, int by) const { return by * nbx + bx; }
};

namespace {

// Arena-world ray cast: Amanatides–Woo traversal of the bucket grid, testing each bucket's walls;
// stops once the nearest hit lies before the current bucket's exit.
double RaycastArena(const WorldIndex& ix, double x, double y, double angle, double max_range) {
  const double dx = std::cos(angle), dy = std::sin(angle);
  // Clip the ray to the grid's box; outside it there are no walls.
  double t0 = 0.0, t1 = max_range;
  auto clip = [&](double o, double d, double lo, double hi) {
    if (d == 0.0) return o >= lo && o <= hi;
    double a = (lo - o) / d, b = (hi - o) / d;
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
    return t0 <= t1;
  };
  if (!(max_range > 0.0) || !clip(x, dx, ix.x0, ix.x1) || !clip(y, dy, ix.y0, ix.y1)) {
    return std::max(max_range, 0.0);
  }
  const double px = x + t0 * dx, py = y + t0 * dy;
  int bx = std::clamp(static_cast<int>(std::floor((px - ix.x0) / ix.bucket)), 0, ix.nbx - 1);
  int by = std::clamp(static_cast<int>(std::floor((py - ix.y0) / ix.bucket)), 0, ix.nby - 1);
  const int step_x = dx > 0 ? 1 : -1, step_y = dy > 0 ? 1 : -1;
  const double inv_dx = dx != 0.0 ? 1.0 / dx : kInf, inv_dy = dy != 0.0 ? 1.0 / dy : kInf;
  auto next_x = [&] { return dx != 0.0 ? (ix.x0 + (bx + (dx > 0)) * ix.bucket - x) * inv_dx : kInf; };
  auto next_y = [&] { return dy != 0.0 ? (ix.y0 + (by + (dy > 0)) * ix.bucket - y) * inv_dy : kInf; };
  double t_max_x = next_x(), t_max_y = next_y();
  double best = max_range;
  for (;;) {
    const int b = ix.BucketIndex(bx, by);
    for (int k = ix.bucket_start[b]; k < ix.bucket_start[b + 1]; ++k) {
      const double s = RayCapsule(ix.capsules[ix.bucket_items[k]], ix.h, x, y, dx, dy);
      if (s < best) best = s;
    }
    const double t_exit = std::min(t_max_x, t_max_y);
    if (best <= t_exit || t_exit >= t1) return best;
    if (t_max_x < t_max_y) {
      bx += step_x;
      if (bx < 0 || bx >= ix.nbx) return best;
      t_max_x = next_x();
    } else {
      by += step_y;
      if (by < 0 || by >= ix.nby) return best;
      t_max_y = next_y();
    }
  }
}

// Grid-world ray cast: Amanatides–Woo over the true map's cells to the first wall cell's boundary;
// outside the grid is wall.
double RaycastGrid(const mapping::OccupancyGrid& g, double x, double y, double angle, double max_range) {
  int cx, cy;
  g.WorldToCell(x, y, &cx, &cy);
  if (!g.IsInside(cx, cy) || g.at(cx, cy) > 0 || !(max_range > 0.0)) return 0.0;
  const double dx = std::cos(angle), dy = std::sin(angle);
  const double res = g.resolution(), ox = g.origin_x(), oy = g.origin_y();
  const int step_x = dx > 0 ? 1 : -1, step_y = dy > 0 ? 1 : -1;
  const double inv_dx = dx != 0.0 ? 1.0 / dx : kInf, inv_dy = dy != 0.0 ? 1.0 / dy : kInf;
  auto next_x = [&] { return dx != 0.0 ? (ox + (cx + (dx > 0)) * res - x) * inv_dx : kInf; };
  auto next_y = [&] { return dy != 0.0 ? (oy + (cy + (dy > 0)) * res - y) * inv_dy : kInf; };
  double t_max_x = next_x(), t_max_y = next_y();
  for (;;) {
    double t;
    if (t_max_x < t_max_y) {
      t = t_max_x;
      cx += step_x;
      t_max_x = next_x();
    } else {
      t = t_max_y;
      cy += step_y;
      t_max_y = next_y();
    }
    if (t >= max_range) return max_range;
    if (!g.IsInside(cx, cy) || g.at(cx, cy) > 0) return std::max(t, 0.0);
  }
}

// Arena world: distance from (x, y) to the nearest wall's centre segment, searching the buckets in
// growing square rings until no unvisited bucket can hold anything nearer.
double NearestSegmentDistance(const WorldIndex& ix, double x, double y) {
  double best2 = kInf;
  const int bx = static_cast<int>(std::floor((x - ix.x0) / ix.bucket));
  const int by = static_cast<int>(std::floor((y - ix.y0) / ix.bucket));
  if (bx < 0 || by < 0 || bx >= ix.nbx || by >= ix.nby) {
    for (const auto& c : ix.capsules) best2 = std::min(best2, SegmentDist2(c, x, y));
    return std::sqrt(best2);
  }
  const int max_ring = std::max({bx, by, ix.nbx - 1 - bx, ix.nby - 1 - by});
  for (int k = 0; k <= max_ring; ++k) {
    for (int j = by - k; j <= by + k; ++j) {
      if (j < 0 || j >= ix.nby) continue;
      const bool edge_row = j == by - k || j == by + k;
      for (int i = bx - k; i <= bx + k; i += edge_row ? 1 : 2 * k) {
        if (i >= 0 && i < ix.nbx) {
          const int b = ix.BucketIndex(i, j);
          for (int q = ix.bucket_start[b]; q < ix.bucket_start[b + 1]; ++q) {
            best2 = std::min(best2, SegmentDist2(ix.capsules[ix.bucket_items[q]], x, y));
          }
        }
        if (k == 0) break;
      }
    }
    // Anything not yet visited lies outside the block of rings 0..k.
    const double reach = std::min({x - (ix.x0 + (bx - k) * ix.bucket), ix.x0 + (bx + k + 1) * ix.bucket - x,
                                   y - (ix.y0 + (by - k) * ix.bucket), ix.y0 + (by + k + 1) * ix.bucket - y});
    if (best2 <= reach * reach) break;
  }
  return std::sqrt(best2);
}

// Grid world: exact distance from (x, y) (inside the grid, in a free cell) to the nearest wall
// cell's square or to the grid's outside, searching cells in square rings; rings nearer than the
// distance transform allows are skipped.
double GridClearance(const mapping::OccupancyGrid& g, const WorldIndex& ix, double x, double y) {
  const double res = g.resolution();
  const double gx0 = g.origin_x(), gy0 = g.origin_y();
  double best = std::min({x - gx0, gx0 + g.width() * res - x, y - gy0, gy0 + g.height() * res - y});
  if (!ix.any_wall_cell) return best;
  int cx, cy;
  g.WorldToCell(x, y, &cx, &cy);
  const double d_centres = ix.centre_distance[static_cast<size_t>(cy) * g.width() + cx];
  // A wall cell k rings away has its centre within k·√2 cells, so rings below D/√2 are empty.
  const int k_first = std::max(0, static_cast<int>(std::floor(d_centres / std::sqrt(2.0) - 1e-3)));
  const int max_ring = std::max({cx, cy, g.width() - 1 - cx, g.height() - 1 - cy});
  for (int k = k_first; k <= max_ring; ++k) {
    // Anything in ring k is at least this far: the gap to the inner block's boundary.
    const double ring_floor = k == 0 ? 0.0
                                     : std::min({x - (gx0 + (cx - k + 1) * res), gx0 + (cx + k) * res - x,
                                                 y - (gy0 + (cy - k + 1) * res), gy0 + (cy + k) * res - y});
    if (ring_floor >= best) break;
    for (int j = cy - k; j <= cy + k; ++j) {
      if (j < 0 || j >= g.height()) continue;
      const bool edge_row = j == cy - k || j == cy + k;
      const double ddy = std::max(0.0, std::abs(y - (gy0 + (j + 0.5) * res)) - 0.5 * res);
      for (int i = cx - k; i <= cx + k; i += edge_row ? 1 : 2 * k) {
        if (i >= 0 && i < g.width() && g.at(i, j) > 0) {
          const double ddx = std::max(0.0, std::abs(x - (gx0 + (i + 0.5) * res)) - 0.5 * res);
          best = std::min(best, std::hypot(ddx, ddy));
        }
        if (k == 0) break;
      }
    }
  }
  return best;
}

}  // namespace

World World::FromSegments(std::vector<WallSegment> walls, double thickness_m, double resolution_m) {
  if (walls.empty()) throw std::runtime_error("a world of segments needs at least one wall");
  if (!(thickness_m >= kMinThickness && thickness_m <= kMaxThickness)) {
    throw std::runtime_error("wall thickness " + Num(thickness_m) + " m out of range [" + Num(kMinThickness) + ", " +
                             Num(kMaxThickness) + "]");
  }
  if (!(resolution_m >= kMinResolution && resolution_m <= kMaxResolution)) {
    throw std::runtime_error("resolution " + Num(resolution_m) + " m out of range [" + Num(kMinResolution) + ", " +
                             Num(kMaxResolution) + "]");
  }
  auto index = std::make_shared<WorldIndex>();
  const double h = 0.5 * thickness_m;
  index->h = h;
  double min_x = kInf, min_y = kInf, max_x = -kInf, max_y = -kInf;
  for (size_t i = 0; i < walls.size(); ++i) {
    const auto& s = walls[i];
    if (!std::isfinite(s.x0) || !std::isfinite(s.y0) || !std::isfinite(s.x1) || !std::isfinite(s.y1)) {
      throw std::runtime_error("wall " + std::to_string(i) + " has a non-finite coordinate");
    }
    const double len = std::hypot(s.x1 - s.x0, s.y1 - s.y0);
    if (!(len > 0.0)) throw std::runtime_error("wall " + std::to_string(i) + " has zero length");
    index->capsules.push_back({s.x0, s.y0, (s.x1 - s.x0) / len, (s.y1 - s.y0) / len, len});
    min_x = std::min({min_x, s.x0, s.x1});
    max_x = std::max({max_x, s.x0, s.x1});
    min_y = std::min({min_y, s.y0, s.y1});
    max_y = std::max({max_y, s.y0, s.y1});
  }
  const double res = resolution_m;
  const double cells_x = (max_x - min_x + 2 * h) / res + 2 * kMarginCells + 2;
  const double cells_y = (max_y - min_y + 2 * h) / res + 2 * kMarginCells + 2;
  if (cells_x > kMaxCellsPerSide || cells_y > kMaxCellsPerSide || cells_x * cells_y > kMaxWorldCells) {
    throw std::runtime_error("the walls span " + Num(max_x - min_x) + " x " + Num(max_y - min_y) +
                             " m, too large for a true map at " + Num(res) + " m (" + Num(std::ceil(cells_x)) + " x " +
                             Num(std::ceil(cells_y)) + " cells; at most " + Num(kMaxCellsPerSide) + " a side and " +
                             Num(kMaxWorldCells) + " in all)");
  }
  // True map: cell-aligned to multiples of the resolution, a margin of free cells around.
  const int gx0 = static_cast<int>(std::floor((min_x - h) / res)) - kMarginCells;
  const int gy0 = static_cast<int>(std::floor((min_y - h) / res)) - kMarginCells;
  const int gx1 = static_cast<int>(std::ceil((max_x + h) / res)) + kMarginCells;
  const int gy1 = static_cast<int>(std::ceil((max_y + h) / res)) + kMarginCells;
  World w;
  w.truth_ = mapping::OccupancyGrid(gx1 - gx0, gy1 - gy0, res, gx0 * res, gy0 * res, -127);
  auto& g = w.truth_;
  const double reach = h + 0.5 * res;  // cell centres this near a segment are wall: no gaps
  for (const auto& c : index->capsules) {
    // Row by row, only the stretch the capsule can reach: the cost grows with a wall's length, not
    // with its bounding box (a long diagonal wall's box holds millions of cells it does not touch).
    const double by0 = std::min(c.ay, c.ay + c.uy * c.len) - reach, by1 = std::max(c.ay, c.ay + c.uy * c.len) + reach;
    int i0, j0, i1, j1;
    g.WorldToCell(c.ax, by0, &i0, &j0);
    g.WorldToCell(c.ax, by1, &i1, &j1);
    for (int j = std::max(j0, 0); j <= std::min(j1, g.height() - 1); ++j) {
      double cx, cy, x_lo, x_hi;
      g.CellToWorld(0, j, &cx, &cy);
      if (!RowSpan(c, cy, reach, &x_lo, &x_hi)) continue;
      int ia, ib, jj;
      g.WorldToCell(x_lo, cy, &ia, &jj);
      g.WorldToCell(x_hi, cy, &ib, &jj);
      for (int i = std::max(ia, 0); i <= std::min(ib, g.width() - 1); ++i) {
        g.CellToWorld(i, j, &cx, &cy);
        if (SegmentDist2(c, cx, cy) <= reach * reach) g.at(i, j) = 127;
      }
    }
  }
  // Bucket grid over the true map's extent.
  index->x0 = g.origin_x();
  index->y0 = g.origin_y();
  index->x1 = g.origin_x() + g.width() * res;
  index->y1 = g.origin_y() + g.height() * res;
  index->bucket = std::max({kBucketSize, (index->x1 - index->x0) / 1024, (index->y1 - index->y0) / 1024});
  index->nbx = std::max(1, static_cast<int>(std::ceil((index->x1 - index->x0) / index->bucket)));
  index->nby = std::max(1, static_cast<int>(std::ceil((index->y1 - index->y0) / index->bucket)));
  std::vector<std::vector<int>> lists(static_cast<size_t>(index->nbx) * index->nby);
  for (size_t k = 0; k < index->capsules.size(); ++k) {
    const auto& c = index->capsules[k];
    const double ey = c.ay + c.uy * c.len;
    auto bucket_of = [&](double v, double o, int n) {
      return std::clamp(static_cast<int>(std::floor((v - o) / index->bucket)), 0, n - 1);
    };
    const int j0 = bucket_of(std::min(c.ay, ey) - h, index->y0, index->nby);
    const int j1 = bucket_of(std::max(c.ay, ey) + h, index->y0, index->nby);
    const double r = h + index->bucket * std::sqrt(0.5);
    for (int j = j0; j <= j1; ++j) {
      // Keep only buckets the capsule really reaches (a diagonal wall's box holds many it does not),
      // looking only along the stretch of this row it can reach.
      const double cy = index->y0 + (j + 0.5) * index->bucket;
      double x_lo, x_hi;
      if (!RowSpan(c, cy, r, &x_lo, &x_hi)) continue;
      const int i0 = bucket_of(x_lo, index->x0, index->nbx), i1 = bucket_of(x_hi, index->x0, index->nbx);
      for (int i = i0; i <= i1; ++i) {
        const double cx = index->x0 + (i + 0.5) * index->bucket;
        if (SegmentDist2(c, cx, cy) <= r * r) lists[index->BucketIndex(i, j)].push_back(static_cast<int>(k));
      }
    }
  }
  index->bucket_start.assign(lists.size() + 1, 0);
  for (size_t b = 0; b < lists.size(); ++b) {
    index->bucket_start[b + 1] = index->bucket_start[b] + static_cast<int>(lists[b].size());
    index->bucket_items.insert(index->bucket_items.end(), lists[b].begin(), lists[b].end());
  }
  w.walls_ = std::move(walls);
  w.thickness_ = thickness_m;
  w.index_ = std::move(index);
  return w;
}

World World::FromGrid(const mapping::OccupancyGrid& grid) {
  if (grid.width() <= 0 || grid.height() <= 0) throw std::runtime_error("a grid world needs a non-empty grid");
  if (static_cast<double>(grid.width()) * grid.height() > kMaxWorldCells) {
    throw std::runtime_error("a map of " + std::to_string(grid.width()) + " x " + std::to_string(grid.height()) +
                             " cells is too large for a world (at most " + Num(kMaxWorldCells) + " cells)");
  }
  World w;
  w.thickness_ = 0.0;
  w.truth_ = mapping::OccupancyGrid(grid.width(), grid.height(), grid.resolution(), grid.origin_x(), grid.origin_y());
  auto index = std::make_shared<WorldIndex>();
  cv::Mat free_mask(grid.height(), grid.width(), CV_8U);
  for (int j = 0; j < grid.height(); ++j) {
    for (int i = 0; i < grid.width(); ++i) {
      const bool wall = grid.at(i, j) >= 0;  // occupied or unknown
      w.truth_.at(i, j) = wall ? 127 : -127;
      free_mask.at<uint8_t>(j, i) = wall ? 0 : 255;
      index->any_wall_cell |= wall;
    }
  }
  if (index->any_wall_cell) {
    cv::Mat dist;
    cv::distanceTransform(free_mask, dist, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
    index->centre_distance.assign(static_cast<size_t>(grid.width()) * grid.height(), 0.0f);
    for (int j = 0; j < grid.height(); ++j) {
      const float* row = dist.ptr<float>(j);
      std::copy(row, row + grid.width(), index->centre_distance.begin() + static_cast<size_t>(j) * grid.width());
    }
  }
  w.index_ = std::move(index);
  return w;
}

double Crate::DistanceTo(double x, double y) const {
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  const double dx = x - pose.x, dy = y - pose.y;
  const double u = std::abs(c * dx + s * dy) - 0.5 * width_m, v = std::abs(-s * dx + c * dy) - 0.5 * depth_m;
  return std::hypot(std::max(u, 0.0), std::max(v, 0.0));
}

double Crate::RayDistance(double x, double y, double angle_rad) const {
  // Slabs in the crate's frame.
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  const double dx = x - pose.x, dy = y - pose.y;
  const double px = c * dx + s * dy, py = -s * dx + c * dy;
  const double a = angle_rad - pose.theta, ux = std::cos(a), uy = std::sin(a);
  double t0 = 0.0, t1 = kInf;
  const double half[2] = {0.5 * width_m, 0.5 * depth_m}, p[2] = {px, py}, u[2] = {ux, uy};
  for (int k = 0; k < 2; ++k) {
    if (std::abs(u[k]) < 1e-15) {
      if (std::abs(p[k]) > half[k]) return kInf;
      continue;
    }
    double ta = (-half[k] - p[k]) / u[k], tb = (half[k] - p[k]) / u[k];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return kInf;
  }
  return t0;
}

// Overlap tests use points every 2 mm round each footprint's edge, and its centre: a wall (at least
// 1 mm thick, and a capsule) or another box cannot lie across an edge between two of them unseen,
// and one box wholly inside another shows by its centre.
std::vector<std::pair<double, double>> Crate::Outline(double step_m) const {
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  std::vector<std::pair<double, double>> points = {{pose.x, pose.y}};
  const double hw = 0.5 * width_m, hd = 0.5 * depth_m;
  const double corners[5][2] = {{-hw, -hd}, {hw, -hd}, {hw, hd}, {-hw, hd}, {-hw, -hd}};
  for (int e = 0; e < 4; ++e) {
    const double ex = corners[e + 1][0] - corners[e][0], ey = corners[e + 1][1] - corners[e][1];
    const int n = std::max(1, static_cast<int>(std::ceil(std::hypot(ex, ey) / step_m)));
    for (int i = 0; i < n; ++i) {
      const double u = corners[e][0] + ex * i / n, v = corners[e][1] + ey * i / n;
      points.emplace_back(pose.x + c * u - s * v, pose.y + s * u + c * v);
    }
  }
  return points;
}

bool Crate::Overlaps(const Crate& other) const {
  // Each footprint lies within its half-diagonal of its centre: farther apart, they cannot touch.
  const double reach = 0.5 * (std::hypot(width_m, depth_m) + std::hypot(other.width_m, other.depth_m));
  if (std::hypot(pose.x - other.pose.x, pose.y - other.pose.y) > reach) return false;
  for (const auto& [x, y] : Outline(0.002)) {
    if (other.DistanceTo(x, y) <= 0.0) return true;
  }
  for (const auto& [x, y] : other.Outline(0.002)) {
    if (DistanceTo(x, y) <= 0.0) return true;
  }
  return false;
}

void World::AddCrate(const Crate& crate) {
  const std::string which = "crate " + std::to_string(crate.id);
  if (!(crate.width_m > 0 && crate.depth_m > 0 && crate.height_m > 0) || !std::isfinite(crate.pose.x) ||
      !std::isfinite(crate.pose.y) || !std::isfinite(crate.pose.theta)) {
    throw std::invalid_argument(which + ": sides must be positive and the pose finite");
  }
  const auto mine = crate.Outline(0.002);
  for (const auto& [x, y] : mine) {
    if (WallsClearanceAt(x, y) <= 0.0) throw std::invalid_argument(which + ": overlaps a wall or leaves the world");
  }
  for (const Crate& other : crates_) {
    if (crate.Overlaps(other)) throw std::invalid_argument(which + ": overlaps crate " + std::to_string(other.id));
  }
  crates_.push_back(crate);
}

double World::RaycastWalls(double x, double y, double angle_rad, double max_range_m) const {
  if (!index_ || !std::isfinite(x) || !std::isfinite(y)) return 0.0;
  return is_grid_world() ? RaycastGrid(truth_, x, y, angle_rad, max_range_m)
                         : RaycastArena(*index_, x, y, angle_rad, max_range_m);
}

double World::Raycast(double x, double y, double angle_rad, double max_range_m) const {
  double range = RaycastWalls(x, y, angle_rad, max_range_m);
  if (range <= 0.0) return range;
  for (const Crate& crate : crates_) {
    if (crate.OnFloor()) range = std::min(range, crate.RayDistance(x, y, angle_rad));
  }
  return range;
}

double World::WallsClearanceAt(double x, double y) const {
  if (!index_ || !std::isfinite(x) || !std::isfinite(y)) return 0.0;
  if (!is_grid_world()) return std::max(0.0, NearestSegmentDistance(*index_, x, y) - index_->h);
  int cx, cy;
  truth_.WorldToCell(x, y, &cx, &cy);
  if (!truth_.IsInside(cx, cy) || truth_.at(cx, cy) > 0) return 0.0;
  return GridClearance(truth_, *index_, x, y);
}

double World::ClearanceAt(double x, double y) const { return ClearanceAt(x, y, -1); }

double World::ClearanceAt(double x, double y, int ignore_crate) const {
  double clearance = WallsClearanceAt(x, y);
  for (size_t i = 0; i < crates_.size(); ++i) {
    if (crates_[i].OnFloor() && static_cast<int>(i) != ignore_crate)
      clearance = std::min(clearance, crates_[i].DistanceTo(x, y));
  }
  return clearance;
}

bool World::Collides(double x, double y, double radius_m) const { return Collides(x, y, radius_m, -1); }

bool World::Collides(double x, double y, double radius_m, int ignore_crate) const {
  for (size_t i = 0; i < crates_.size(); ++i) {
    if (crates_[i].OnFloor() && static_cast<int>(i) != ignore_crate &&
        crates_[i].DistanceTo(x, y) <= std::max(radius_m, 0.0))
      return true;
  }
  return WallsCollide(x, y, radius_m);
}

bool World::WallsCollide(double x, double y, double radius_m) const {
  if (!index_) return true;
  const double r = std::max(radius_m, 0.0);
  const double x0 = truth_.origin_x(), y0 = truth_.origin_y();
  const double x1 = x0 + truth_.width() * truth_.resolution(), y1 = y0 + truth_.height() * truth_.resolution();
  if (!(x - r >= x0 && x + r < x1 && y - r >= y0 && y + r < y1)) return true;  // leaves the world (or NaN)
  if (is_grid_world()) {
    int cx, cy;
    truth_.WorldToCell(x, y, &cx, &cy);
    if (truth_.at(cx, cy) > 0) return true;
    if (index_->any_wall_cell) {
      // Quick reject: the distance transform bounds the clearance from below by D − √2 cells.
      const double lower =
          (index_->centre_distance[static_cast<size_t>(cy) * truth_.width() + cx] - std::sqrt(2.0) - 1e-3) *
          truth_.resolution();
      if (lower > r) return false;
    }
    return GridClearance(truth_, *index_, x, y) <= r;
  }
  // Arena world: the walls in the buckets the disc's box touches.
  const WorldIndex& ix = *index_;
  const double reach = r + ix.h;
  const int i0 = std::clamp(static_cast<int>(std::floor((x - r - ix.x0) / ix.bucket)), 0, ix.nbx - 1);
  const int i1 = std::clamp(static_cast<int>(std::floor((x + r - ix.x0) / ix.bucket)), 0, ix.nbx - 1);
  const int j0 = std::clamp(static_cast<int>(std::floor((y - r - ix.y0) / ix.bucket)), 0, ix.nby - 1);
  const int j1 = std::clamp(static_cast<int>(std::floor((y + r - ix.y0) / ix.bucket)), 0, ix.nby - 1);
  for (int j = j0; j <= j1; ++j) {
    for (int i = i0; i <= i1; ++i) {
      const int b = ix.BucketIndex(i, j);
      for (int k = ix.bucket_start[b]; k < ix.bucket_start[b + 1]; ++k) {
        if (SegmentDist2(ix.capsules[ix.bucket_items[k]], x, y) <= reach * reach) return true;
      }
    }
  }
  return false;
}

std::vector<motion::Pose2D> World::PosesLabelled(const std::string& label) const {
  std::vector<motion::Pose2D> out;
  for (const auto& p : poses_) {
    if (p.label == label) out.push_back(p.pose);
  }
  return out;
}

namespace {

// The true map's cell of `start`, as an index; throws, naming `who`, when it is not a free one.
int StartCell(const World& world, const motion::Pose2D& start, const char* who) {
  const auto& g = world.truth();
  int sx, sy;
  g.WorldToCell(start.x, start.y, &sx, &sy);
  if (!g.IsInside(sx, sy) || g.at(sx, sy) >= 0) {
    throw std::runtime_error(std::string(who) + ": start (" + Num(start.x) + ", " + Num(start.y) +
                             ") is not in a free cell of the true map of '" + world.name() + "'");
  }
  return sy * g.width() + sx;
}

// The true map's free cells.
std::vector<uint8_t> FreeCells(const mapping::OccupancyGrid& g) {
  std::vector<uint8_t> free(g.cells().size());
  for (size_t i = 0; i < free.size(); ++i) free[i] = g.cells()[i] < 0;
  return free;
}

// The cells 4-connected to `start` through cells `passable` (indexed as the true map's), `start` included.
std::vector<uint8_t> Flood(const mapping::OccupancyGrid& g, int start, const std::vector<uint8_t>& passable) {
  std::vector<uint8_t> mask(g.cells().size(), 0);
  std::vector<int> stack{start};
  mask[start] = 1;
  while (!stack.empty()) {
    const int c = stack.back();
    stack.pop_back();
    const int cx = c % g.width(), cy = c / g.width();
    const int nx[4] = {cx + 1, cx - 1, cx, cx};
    const int ny[4] = {cy, cy, cy + 1, cy - 1};
    for (int k = 0; k < 4; ++k) {
      if (!g.IsInside(nx[k], ny[k])) continue;
      const int n = ny[k] * g.width() + nx[k];
      if (!mask[n] && passable[n]) {
        mask[n] = 1;
        stack.push_back(n);
      }
    }
  }
  return mask;
}

}  // namespace

std::vector<uint8_t> ReachableFreeMask(const World& world, const motion::Pose2D& start) {
  return Flood(world.truth(), StartCell(world, start, "ReachableFreeMask"), FreeCells(world.truth()));
}

std::vector<uint8_t> BodyReachableMask(const World& world, const motion::Pose2D& start, double radius_m) {
  const auto& g = world.truth();
  const int start_cell = StartCell(world, start, "BodyReachableMask");
  const int w = g.width(), h = g.height();
  // Where the centre may be: free cells with room for the body (the start's cell always).
  std::vector<uint8_t> roomy(g.cells().size(), 0);
  for (int j = 0; j < h; ++j) {
    for (int i = 0; i < w; ++i) {
      if (g.at(i, j) >= 0) continue;
      double x, y;
      g.CellToWorld(i, j, &x, &y);
      roomy[static_cast<size_t>(j) * w + i] = world.ClearanceAt(x, y) >= radius_m;
    }
  }
  roomy[start_cell] = 1;
  const std::vector<uint8_t> centre = Flood(g, start_cell, roomy);
  // The body: free cells within the radius of a centre cell (the centre's clearance keeps the disc
  // free of walls, so nothing behind a wall is reached).
  cv::Mat not_centre(h, w, CV_8U);
  for (int j = 0; j < h; ++j) {
    for (int i = 0; i < w; ++i) not_centre.at<uint8_t>(j, i) = centre[static_cast<size_t>(j) * w + i] ? 0 : 255;
  }
  cv::Mat dist;
  cv::distanceTransform(not_centre, dist, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  const double reach_cells = radius_m / g.resolution() + 0.5;
  std::vector<uint8_t> body(g.cells().size(), 0);
  for (int j = 0; j < h; ++j) {
    const float* row = dist.ptr<float>(j);
    for (int i = 0; i < w; ++i) {
      body[static_cast<size_t>(j) * w + i] = g.at(i, j) < 0 && row[i] <= reach_cells;
    }
  }
  return body;
}

namespace {

// The world's reachable free space as a mask over its true map (every free cell without a start).
std::vector<uint8_t> ReachableFromStart(const World& world) {
  const std::vector<motion::Pose2D> starts = world.PosesLabelled("start");
  if (!starts.empty()) return ReachableFreeMask(world, starts.front());
  return FreeCells(world.truth());
}

}  // namespace

mapping::OccupancyGrid RenderKnownMap(const World& world, double resolution_m) {
  if (!(resolution_m > 0)) throw std::invalid_argument("RenderKnownMap: resolution must be positive");
  const mapping::OccupancyGrid& t = world.truth();
  const std::vector<uint8_t> reach = ReachableFromStart(world);
  const double w = t.width() * t.resolution(), h = t.height() * t.resolution();
  const int nx = static_cast<int>(std::ceil(w / resolution_m)), ny = static_cast<int>(std::ceil(h / resolution_m));
  mapping::OccupancyGrid m(nx, ny, resolution_m, t.origin_x(), t.origin_y());
  for (int cy = 0; cy < ny; ++cy) {
    for (int cx = 0; cx < nx; ++cx) {
      double x, y;
      m.CellToWorld(cx, cy, &x, &y);
      // Occupied when a wall comes within half a cell side of the centre (what a mapped wall looks
      // like; half a diagonal would also take cells a wall merely grazes, fattening every wall).
      if (world.ClearanceAt(x, y) <= 0.5 * resolution_m) {
        m.at(cx, cy) = 127;
        continue;
      }
      int tx, ty;
      t.WorldToCell(x, y, &tx, &ty);
      if (t.IsInside(tx, ty) && reach[static_cast<size_t>(ty) * t.width() + tx]) m.at(cx, cy) = -127;
    }
  }
  return m;
}

EventInputs EventInputsOf(const World& world) {
  EventInputs in;
  const std::vector<motion::Pose2D> starts = world.PosesLabelled("start");
  if (!starts.empty()) {
    const motion::Pose2D inv = starts[0].Inverse();
    for (const motion::Pose2D& w : world.PosesLabelled("waypoint")) in.waypoints.push_back(inv.Compose(w));
  }
  in.targets = world.PosesLabelled("target");
  in.dropoffs = world.PosesLabelled("dropoff");
  in.stacks = world.stacks();
  return in;
}

motion::Pose2D RandomFreePose(const World& world, double clearance_m, uint64_t seed) {
  const mapping::OccupancyGrid& t = world.truth();
  const std::vector<uint8_t> reach = ReachableFromStart(world);
  std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ULL + 0x5157A27);
  std::uniform_real_distribution<double> ux(t.origin_x(), t.origin_x() + t.width() * t.resolution());
  std::uniform_real_distribution<double> uy(t.origin_y(), t.origin_y() + t.height() * t.resolution());
  std::uniform_real_distribution<double> uth(-M_PI, M_PI);
  for (int i = 0; i < 10'000; ++i) {
    const double x = ux(rng), y = uy(rng);
    int cx, cy;
    t.WorldToCell(x, y, &cx, &cy);
    if (!t.IsInside(cx, cy) || !reach[static_cast<size_t>(cy) * t.width() + cx]) continue;
    if (world.ClearanceAt(x, y) < clearance_m) continue;
    return {x, y, uth(rng)};
  }
  throw std::runtime_error("RandomFreePose: no place in '" + world.name() + "' keeps " + Num(clearance_m) +
                           " m from every wall (10,000 draws)");
}

motion::Pose2D MostRoomPose(const World& world, uint64_t seed) {
  const mapping::OccupancyGrid& t = world.truth();
  double best = 0.0;
  std::vector<std::pair<double, int>> room;  // clearance, cell
  for (int j = 0; j < t.height(); ++j) {
    for (int i = 0; i < t.width(); ++i) {
      if (t.at(i, j) >= 0) continue;
      double x, y;
      t.CellToWorld(i, j, &x, &y);
      const double c = world.ClearanceAt(x, y);
      if (c < best - 0.5 * t.resolution()) continue;
      best = std::max(best, c);
      room.emplace_back(c, j * t.width() + i);
    }
  }
  std::vector<int> widest;
  for (const auto& [c, cell] : room) {
    if (c >= best - 0.5 * t.resolution()) widest.push_back(cell);
  }
  if (widest.empty() || !(best > 0.0)) throw std::runtime_error("'" + world.name() + "' has no free cell to start in");
  std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ULL + 0x5747A27);
  const int cell = widest[std::uniform_int_distribution<size_t>(0, widest.size() - 1)(rng)];
  double x, y;
  t.CellToWorld(cell % t.width(), cell / t.width(), &x, &y);
  return {x, y, std::uniform_real_distribution<double>(-M_PI, M_PI)(rng)};
}

void PlaceCratesAtRandom(World* world, const CrateArea& area, uint64_t seed, const motion::Pose2D& keep_clear,
                         double keep_clear_m) {
  std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ULL + 0xC2A7E5);
  std::uniform_real_distribution<double> u(-0.5 * area.side_m, 0.5 * area.side_m), uth(-M_PI, M_PI);
  int placed = 0;
  for (int draw = 0; draw < 10'000 && placed < area.count; ++draw) {
    Crate c;
    c.id = area.first_id + placed;
    c.pose = {area.x + u(rng), area.y + u(rng), uth(rng)};
    // The whole footprint inside the square, and clear of the start.
    const double reach = 0.5 * std::hypot(c.width_m, c.depth_m);
    if (std::abs(c.pose.x - area.x) + reach > 0.5 * area.side_m ||
        std::abs(c.pose.y - area.y) + reach > 0.5 * area.side_m)
      continue;
    if (c.DistanceTo(keep_clear.x, keep_clear.y) < keep_clear_m) continue;
    // Room between crates for the robot to come up to each (its forklift needs a clear face).
    bool crowded = false;
    for (const Crate& other : world->crates()) {
      for (const auto& [x, y] : other.Outline(0.01)) crowded = crowded || c.DistanceTo(x, y) < area.min_gap_m;
    }
    if (crowded) continue;
    try {
      world->AddCrate(c);
    } catch (const std::invalid_argument&) {
      continue;  // on a wall or another crate: draw again
    }
    ++placed;
  }
  if (placed < area.count) {
    throw std::runtime_error("crates_at_random: only " + std::to_string(placed) + " of " + std::to_string(area.count) +
                             " crates fit in the " + Num(area.side_m) + " m square at (" + Num(area.x) + ", " +
                             Num(area.y) + ") of '" + world->name() + "' (10,000 draws)");
  }
}

}  // namespace mbot::sim
