// The normal-distributions transform of a log-odds map (Biber and Straßer, "The Normal
// Distributions Transform: A New Approach to Laser Scan Matching", IROS 2003), for placing a scan
// between cells. Each cell keeps the moments of the hits that ended in it (HitMoments); a point is
// scored against the Gaussian of the hits in the 3 × 3 cells around it, where the map holds one of
// those cells occupied and the point's own cell holds hits. A wall's hits spread over two cells
// when it lies near their border and the lidar's noise is a good part of a cell: a likelihood
// field of whole cells is then flat over that band (±1° of heading changed the MBot's scan's
// log-likelihood by a few units in a maze), while the hits' mean and spread still place the wall
// to a fraction of the noise.
#pragma once

#include <cstdint>
#include <vector>

#include "mbot/mapping/moving_scan.hpp"
#include "mbot/mapping/occupancy_grid.hpp"
#include "mbot/motion/pose2d.hpp"

namespace mbot::mapping {

// Per cell: the hits' summed weight, sums and sums of squares of their offsets from the cell's
// centre (each hit counted with its weight), and how many hits there were.
struct CellMoments {
  float n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
  float hits = 0;
};

// The moments of every cell of a grid, kept beside it (same width, height and origin), apart by
// the direction the ray came from (eight sectors of 45°). A point is scored on the hits of its own
// ray's sector and the two beside it: a thin wall's two faces, seen from opposite sides, never pool
// (pooled, each face would lie in the wall's middle), and a wall beside the robot, first seen from
// ahead, keeps its hits as the robot passes it.
class HitMoments {
 public:
  static constexpr int kDirections = 8;
  // The sector of a ray's direction [rad, map frame].
  static int DirectionOf(double angle_rad);
  // The most cells a grid may have for its moments (kDirections × 28 bytes a cell) to stay within
  // the memory a grid of kMaxGridCells cells of one byte may take.
  static constexpr long long kMaxCells = kMaxGridCells / (kDirections * static_cast<long long>(sizeof(CellMoments)));
  // Sized for `grid`, all zero.
  void Reset(const OccupancyGrid& grid);
  // After `grid` grew by `left` and `bottom` cells on those sides (and others on the far sides): the
  // moments move with their cells.
  void Grow(const OccupancyGrid& grid, int left, int bottom);
  // A hit at (x, y) in cell (cx, cy) of `grid`, by a ray in direction `direction` (DirectionOf),
  // counted `weight` times (MapperOptions::hit_range_power).
  void Add(const OccupancyGrid& grid, int cx, int cy, double x, double y, int direction, double weight = 1.0);
  const CellMoments& at(int cx, int cy, int direction) const {
    return cells_[(static_cast<size_t>(cy) * width_ + cx) * kDirections + direction];
  }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  int width_ = 0, height_ = 0;
  std::vector<CellMoments> cells_;
};

struct NdtOptions {
  int occupied_threshold = 0;   // a block with a cell above this log-odds lends its hits
  int min_hits = 10;            // a block with fewer hits (counted, not weighed) scores nothing
  double min_sigma_m = 0.01;    // added to every Gaussian's spread (a wall seen once is not a line)
  double outlier_sigmas = 3.0;  // points farther than this (Mahalanobis) from their block's mean weigh less
  // Pulls towards the initial pose: 1 / the prior's standard deviation (0: none), 5 cm and 6° by
  // default, looser than a particle filter's spread: its estimate is a mean over whole cells.
  double translation_weight = 20.0;  // [1/m]
  double rotation_weight = 10.0;     // [1/rad]
  int max_iterations = 10;
  // Each hit weighs (its range / 1 m)^range_power in the moments the fit uses: full SLAM passes it
  // to its mapper as MapperOptions::hit_range_power (why: there; figures: BENCHMARKS.md, "Maze 27").
  double range_power = 2.0;
};

struct NdtResult {
  motion::Pose2D pose;
  int points_used = 0;  // points with a Gaussian, at the start of the last step
};

// A scan's hit in the robot frame and the direction of its ray there [rad].
struct NdtPoint {
  float x = 0, y = 0, direction = 0;
};
std::vector<NdtPoint> NdtPoints(const std::vector<ScanRay>& rays);

// The pose that best places `points` on the hits' Gaussians (those seen from the same direction), by Gauss–Newton from
// `initial` with Huber weights beyond outlier_sigmas. Too few points with a Gaussian (under 10):
// `initial` unchanged.
NdtResult RefineNdt(const OccupancyGrid& grid, const HitMoments& moments, const std::vector<NdtPoint>& points,
                    const motion::Pose2D& initial, const NdtOptions& options);

}  // namespace mbot::mapping
