// Distance from every cell to the nearest obstacle cell, in metres: an exact Euclidean distance
// transform (Felzenszwalb & Huttenlocher's lower-envelope pass per row and column), so the result
// equals a brushfire whose wavefront carries the true Euclidean distance between cell centres.
// Kept up to date incrementally: Update recomputes only what the cells that changed can reach.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "mbot/mapping/distance_transform.hpp"
#include "mbot/mapping/occupancy_grid.hpp"

namespace mbot::planning {

struct ObstacleDistanceOptions {
  // Unknown cells (log-odds 0) count as obstacles when true, as free space when false. The botlab
  // planner tests treat unknown as free; exploration treats it as blocked so paths stay in mapped space.
  bool unknown_is_obstacle = false;
  // Cells with log-odds above this are obstacles (the botlab rule is > 0).
  int occupied_threshold = 0;
  // With unknown_is_obstacle: an unknown cell counts as an obstacle this much farther away than it
  // is, so a robot may come this much closer to unseen space than to a wall (0: the same). The
  // clearance a planner needs from walls covers the grid's error (a thin wall anywhere in its cell,
  // the robot anywhere in its own); unseen space only has to stay out of the footprint.
  double unknown_margin_m = 0.0;
  // With unknown_is_obstacle: a cell counts as unknown unless its log-odds is at or below this
  // (and it is not an obstacle). -1: every free cell is known (the botlab rule, < 0 is free);
  // exploration asks for the frontiers' confidence, so faint cells seen by a few grazing rays (a
  // thin wall's end, a corridor glimpsed at a slant) are not driven through as if they were free.
  int free_threshold = -1;
};

class ObstacleDistanceGrid {
 public:
  static constexpr float kInfinity = std::numeric_limits<float>::infinity();

  ObstacleDistanceGrid() = default;
  // No map yet: the first Update builds everything.
  explicit ObstacleDistanceGrid(const ObstacleDistanceOptions& options) : options_(options) {}
  // Builds the distances for `map` (same size, resolution and origin). A map without any obstacle
  // gives kInfinity everywhere.
  ObstacleDistanceGrid(const mapping::OccupancyGrid& map, const ObstacleDistanceOptions& options);

  // Brings the distances up to date with a new version of the map, with the options built with:
  // only the columns holding cells that changed class (obstacle, unknown, free) and then the rows
  // whose column distances changed are recomputed; the result equals a build from scratch.
  // Returns the cells whose distance changed: the whole grid when the map's size, resolution or
  // origin changed (or on the first map), empty when nothing did.
  mapping::CellRect Update(const mapping::OccupancyGrid& map);
  // Recomputes everything from scratch, reusing the buffers.
  void Recompute(const mapping::OccupancyGrid& map);

  const ObstacleDistanceOptions& options() const { return options_; }

  int width() const { return width_; }
  int height() const { return height_; }
  double resolution() const { return resolution_; }
  double origin_x() const { return origin_x_; }
  double origin_y() const { return origin_y_; }
  bool IsInside(int cx, int cy) const { return cx >= 0 && cy >= 0 && cx < width_ && cy < height_; }
  // Distance [m] between the centre of (cx, cy) and the centre of the nearest obstacle cell; 0 on
  // obstacles.
  float at(int cx, int cy) const { return dist_[static_cast<size_t>(cy) * width_ + cx]; }
  const std::vector<float>& distances() const { return dist_; }
  void WorldToCell(double x, double y, int* cx, int* cy) const;
  void CellToWorld(int cx, int cy, double* x, double* y) const;

 private:
  int width_ = 0;
  int height_ = 0;
  double resolution_ = 0.05;
  double origin_x_ = 0.0;
  double origin_y_ = 0.0;
  std::vector<float> dist_;
  ObstacleDistanceOptions options_;
  // The transforms of the obstacle cells and (with a separate unknown margin) of the unknown cells.
  mapping::EuclideanDistanceTransform obstacles_, unknown_;
  std::vector<uint8_t> obstacle_mask_, unknown_mask_;  // scratch, kept to save the allocations

  bool SeparateUnknown() const { return options_.unknown_is_obstacle && options_.unknown_margin_m > 0; }
  void Masks(const mapping::OccupancyGrid& map);
  void Distances(const mapping::CellRect& rect);
};

}  // namespace mbot::planning
