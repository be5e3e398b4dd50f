// Scan-to-map matching for graph SLAM (Hess et al., "Real-Time Loop Closure in 2D LIDAR SLAM",
// ICRA 2016, §IV–V):
//  - MatchGrid: a smooth likelihood field over an occupancy grid, exp(-d²/2σ²) of each cell's
//    distance to the nearest occupied cell in 1/255 steps, with a stack of max-pooled levels (level
//    h holds the maximum over each 2^h × 2^h block) for the branch-and-bound search;
//  - MatchBranchAndBound: the correlative search over a window of translations and rotations,
//    exhaustive in result (the best-scoring pose on the window's lattice) but pruned through the
//    levels' upper bounds;
//  - RefineMatch: a Ceres least-squares fit of the pose, bicubic over the field, held near the
//    search's answer by translation and rotation priors.
// Scores are the mean field value over the scan's points, in [0, 1].
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "mbot/mapping/moving_scan.hpp"
#include "mbot/mapping/occupancy_grid.hpp"
#include "mbot/motion/pose2d.hpp"

namespace mbot::mapping {

struct Point2 {
  float x = 0, y = 0;
};

// The hit end points of `rays` (robot frame), thinned so that no two lie within `min_spacing_m`
// along the scan (0: every hit).
std::vector<Point2> ScanHitPoints(const std::vector<ScanRay>& rays, double min_spacing_m = 0.0);

class MatchGrid {
 public:
  MatchGrid() = default;
  // The field of `grid` (cells above `occupied_threshold` are obstacles) with `levels` max-pooled
  // levels for the search (1: only the finest).
  MatchGrid(const OccupancyGrid& grid, double sigma_m, int occupied_threshold, int levels);

  bool empty() const { return width_ == 0; }
  int width() const { return width_; }
  int height() const { return height_; }
  double resolution() const { return resolution_; }
  double origin_x() const { return origin_x_; }
  double origin_y() const { return origin_y_; }
  int levels() const { return static_cast<int>(levels_.size()); }
  // The field at a cell (0 off the grid).
  float At(int cx, int cy) const {
    return (unsigned)cx < (unsigned)width_ && (unsigned)cy < (unsigned)height_
               ? levels_[0][static_cast<size_t>(cy) * width_ + cx] * (1.0f / 255.0f)
               : 0.0f;
  }
  // Level h's bound for the block whose lowest cell is (cx, cy), in 0..255.
  int Bound(int h, int cx, int cy) const {
    const int pad = (1 << h) - 1, w = width_ + pad;
    const int x = cx + pad, y = cy + pad;
    return (unsigned)x < (unsigned)w && (unsigned)y < (unsigned)(height_ + pad)
               ? levels_[h][static_cast<size_t>(y) * w + x]
               : 0;
  }
  // Mean field value of `points` placed at `pose` (nearest cell).
  double Score(const motion::Pose2D& pose, const std::vector<Point2>& points) const;
  size_t bytes() const;

 private:
  int width_ = 0, height_ = 0;
  double resolution_ = 0.05, origin_x_ = 0, origin_y_ = 0;
  // Level 0 is the field in 1/255 steps; level h ≥ 1 is (width + 2^h − 1) × (height + 2^h − 1).
  std::vector<std::vector<uint8_t>> levels_;
};

struct SearchWindow {
  double linear_m = 0.1;     // ± in x and y
  double angular_rad = 0.3;  // ± in heading
  // Angular step: the rotation that moves the farthest point by one cell, but never finer than this.
  double min_angular_step_rad = 0.0;
};

struct MatchResult {
  bool found = false;
  motion::Pose2D pose;
  double score = 0;
  int64_t evaluated = 0;  // candidate poses scored, at every level
};

// The best pose of `points` on `grid` within `window` around `initial` whose score reaches
// `min_score`; found = false when none does.
MatchResult MatchBranchAndBound(const MatchGrid& grid, const std::vector<Point2>& points, const motion::Pose2D& initial,
                                const SearchWindow& window, double min_score);

// How firmly a scan can pin its own position down, from its geometry alone: the information of its
// surfaces, Σ n nᵀ over the points' normals (from their neighbours along the scan), per point. A
// room's scan faces every way (weak ≈ strong); a corridor's faces across it only (weak ≈ 0), so a
// match of it says nothing about the position along the corridor — whatever a submap's wall ends
// or its gaps between sparse far returns suggest. The weak axis is turned by `theta` (the scan's
// heading) into the map's frame.
struct TranslationConstraint {
  double strong = 0, weak = 0;  // the eigenvalues of the mean n nᵀ: strong + weak = 1
  double weak_axis_rad = 0;     // the direction the scan can slide along
  double ratio() const { return strong > 0 ? std::max(weak, 0.0) / strong : 0.0; }
};
TranslationConstraint ScanTranslationConstraint(const std::vector<Point2>& points, double theta);

// A whole-map search: the best pose of `points` anywhere on `map` at any heading (branch and bound
// over every cell and rotation, then refined), for a lost robot or a session that starts on a
// finished map. found = false when no pose scores `min_score`.
MatchResult GlobalMatch(const OccupancyGrid& map, const std::vector<Point2>& points, double sigma_m,
                        int occupied_threshold, double min_score, double min_angular_step_rad = 0.005);

struct RefineOptions {
  double occupied_weight = 1.0;     // of the field term (summed over points, scaled by 1/√n)
  double translation_weight = 1.0;  // pull towards the initial position, per metre
  double rotation_weight = 4.0;     // pull towards the initial heading, per radian
  int max_iterations = 20;
};

// The pose minimising Σ (√(1 − field))² + priors, starting from `initial`.
motion::Pose2D RefineMatch(const MatchGrid& grid, const std::vector<Point2>& points, const motion::Pose2D& initial,
                           const RefineOptions& options);

}  // namespace mbot::mapping
