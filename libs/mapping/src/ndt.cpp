#include "mbot/mapping/ndt.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Dense>

namespace mbot::mapping {

int HitMoments::DirectionOf(double angle_rad) {
  const double a = motion::WrapAngle(angle_rad) + M_PI;  // [0, 2π]
  return std::clamp(static_cast<int>(a / (2 * M_PI / kDirections)), 0, kDirections - 1);
}

void HitMoments::Reset(const OccupancyGrid& grid) {
  width_ = grid.width();
  height_ = grid.height();
  cells_.assign(static_cast<size_t>(width_) * height_ * kDirections, CellMoments{});
}

void HitMoments::Grow(const OccupancyGrid& grid, int left, int bottom) {
  std::vector<CellMoments> grown(static_cast<size_t>(grid.width()) * grid.height() * kDirections);
  for (int y = 0; y < height_; ++y) {
    std::copy_n(&cells_[static_cast<size_t>(y) * width_ * kDirections], width_ * kDirections,
                &grown[(static_cast<size_t>(y + bottom) * grid.width() + left) * kDirections]);
  }
  width_ = grid.width();
  height_ = grid.height();
  cells_ = std::move(grown);
}

void HitMoments::Add(const OccupancyGrid& grid, int cx, int cy, double x, double y, int direction, double weight) {
  if (grid.width() != width_ || grid.height() != height_) throw std::logic_error("hit moments: not the grid's size");
  double mx, my;
  grid.CellToWorld(cx, cy, &mx, &my);
  const float dx = static_cast<float>(x - mx), dy = static_cast<float>(y - my);
  CellMoments& m = cells_[(static_cast<size_t>(cy) * width_ + cx) * kDirections + direction];
  const float w = static_cast<float>(weight);
  m.n += w;
  m.hits += 1;
  m.sx += w * dx, m.sy += w * dy;
  m.sxx += w * dx * dx, m.sxy += w * dx * dy, m.syy += w * dy * dy;
}

namespace {

// The Gaussian of the hits in the 3 × 3 cells around (cx, cy), in world coordinates.
struct Block {
  Eigen::Vector2d mean;
  Eigen::Matrix2d information;  // the inverse covariance
};

bool BlockAt(const OccupancyGrid& grid, const HitMoments& moments, int cx, int cy, int direction, const NdtOptions& o,
             Block* b) {
  const double res = grid.resolution();
  const int x0 = std::max(0, cx - 1), x1 = std::min(grid.width() - 1, cx + 1);
  const int y0 = std::max(0, cy - 1), y1 = std::min(grid.height() - 1, cy + 1);
  // A block the map holds a wall in lends all its hits: a wall's hits either side of its surface
  // are its noise, and the cell in front of it, which every longer ray crosses, may be held free.
  // Gating each cell alone would keep only the far side's hits and move the wall back.
  bool wall = false;
  for (int y = y0; y <= y1 && !wall; ++y)
    for (int x = x0; x <= x1; ++x)
      wall = wall || grid.cells()[static_cast<size_t>(y) * grid.width() + x] > o.occupied_threshold;
  // The point's own cell must hold hits seen this way: next to the last hits seen (a wall's end, or
  // as far along it as was seen), the block's mean lies behind the point and would pull the scan back.
  // Hits seen from within one direction sector of the point's ray count: both faces of a thin wall
  // never meet, and a cell beside the robot, first seen from ahead, keeps its hits as it passes.
  const int sectors[3] = {(direction + HitMoments::kDirections - 1) % HitMoments::kDirections, direction,
                          (direction + 1) % HitMoments::kDirections};
  auto hits_at = [&](int x, int y) {
    return moments.at(x, y, sectors[0]).hits + moments.at(x, y, sectors[1]).hits + moments.at(x, y, sectors[2]).hits;
  };
  if (!wall || hits_at(cx, cy) <= 0) return false;
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0, hits = 0;
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      for (const int k : sectors) {
        const CellMoments& m = moments.at(x, y, k);
        if (m.n <= 0) continue;
        // Offsets from the block's centre cell: each cell's lie (x − cx, y − cy) cells off it.
        const double ox = (x - cx) * res, oy = (y - cy) * res;
        n += m.n;
        hits += m.hits;
        sx += m.sx + m.n * ox;
        sy += m.sy + m.n * oy;
        sxx += m.sxx + 2 * ox * m.sx + m.n * ox * ox;
        syy += m.syy + 2 * oy * m.sy + m.n * oy * oy;
        sxy += m.sxy + ox * m.sy + oy * m.sx + m.n * ox * oy;
      }
    }
  }
  if (hits < o.min_hits) return false;
  const double mx = sx / n, my = sy / n;
  const double s0 = o.min_sigma_m * o.min_sigma_m;
  Eigen::Matrix2d cov;
  cov << std::max(0.0, sxx / n - mx * mx) + s0, sxy / n - mx * my, sxy / n - mx * my,
      std::max(0.0, syy / n - my * my) + s0;
  double ccx, ccy;
  grid.CellToWorld(cx, cy, &ccx, &ccy);
  b->mean = {ccx + mx, ccy + my};
  b->information = cov.inverse();
  if (!std::isfinite(b->information(0, 0)) || !std::isfinite(b->information(1, 1))) return false;
  return true;
}

}  // namespace

std::vector<NdtPoint> NdtPoints(const std::vector<ScanRay>& rays) {
  std::vector<NdtPoint> out;
  out.reserve(rays.size());
  for (const ScanRay& r : rays) {
    if (!r.hit || !std::isfinite(r.ex) || !std::isfinite(r.ey)) continue;
    out.push_back({r.ex, r.ey, static_cast<float>(std::atan2(r.ey - r.oy, r.ex - r.ox))});
  }
  return out;
}

NdtResult RefineNdt(const OccupancyGrid& grid, const HitMoments& moments, const std::vector<NdtPoint>& points,
                    const motion::Pose2D& initial, const NdtOptions& o) {
  NdtResult out;
  out.pose = initial;
  if (moments.width() != grid.width() || moments.height() != grid.height() || points.empty()) return out;
  const double kt = o.translation_weight * o.translation_weight, kr = o.rotation_weight * o.rotation_weight;
  motion::Pose2D pose = initial;
  for (int it = 0; it < o.max_iterations; ++it) {
    const double c = std::cos(pose.theta), s = std::sin(pose.theta);
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    int used = 0;
    for (const NdtPoint& q : points) {
      const double px = pose.x + c * q.x - s * q.y, py = pose.y + s * q.x + c * q.y;
      int cx, cy;
      grid.WorldToCell(px, py, &cx, &cy);
      if (cx < 0 || cy < 0 || cx >= grid.width() || cy >= grid.height()) continue;
      Block b;
      if (!BlockAt(grid, moments, cx, cy, HitMoments::DirectionOf(pose.theta + q.direction), o, &b)) continue;
      const Eigen::Vector2d d(px - b.mean.x(), py - b.mean.y());
      const double m2 = d.dot(b.information * d);
      // Huber: full weight within outlier_sigmas, then falling as 1/distance.
      const double m = std::sqrt(m2);
      const double w = m <= o.outlier_sigmas ? 1.0 : o.outlier_sigmas / m;
      Eigen::Matrix<double, 2, 3> j;
      j << 1, 0, -s * q.x - c * q.y, 0, 1, c * q.x - s * q.y;
      const Eigen::Matrix<double, 3, 2> jt_info = j.transpose() * b.information;
      h += w * jt_info * j;
      g += w * jt_info * d;
      ++used;
    }
    out.points_used = used;
    if (used < 10) {
      out.pose = initial;
      return out;
    }
    // The priors: information kt on x and y, kr on heading, towards `initial` — scaled as one
    // point's worth per unit weight, so the scan's many points decide where they agree.
    h(0, 0) += kt, h(1, 1) += kt, h(2, 2) += kr;
    g(0) += kt * (pose.x - initial.x);
    g(1) += kt * (pose.y - initial.y);
    g(2) += kr * motion::WrapAngle(pose.theta - initial.theta);
    const Eigen::Vector3d step = -h.ldlt().solve(g);
    if (!step.allFinite()) break;
    pose.x += step(0);
    pose.y += step(1);
    pose.theta = motion::WrapAngle(pose.theta + step(2));
    if (std::abs(step(0)) < 1e-5 && std::abs(step(1)) < 1e-5 && std::abs(step(2)) < 1e-5) break;
  }
  out.pose = pose;
  return out;
}

}  // namespace mbot::mapping
