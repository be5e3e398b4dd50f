// Log-odds occupancy mapping: every ray lowers the cells it crosses (Bresenham) by `miss_odds` and,
// when it hit something, raises its end cell by `hit_odds`, saturating at ±127. The grid either
// keeps a fixed extent or grows (by whole blocks, keeping its cells) when a scan reaches its edge.
#pragma once

#include <vector>

#include "mbot/mapping/moving_scan.hpp"
#include "mbot/mapping/ndt.hpp"
#include "mbot/mapping/occupancy_grid.hpp"
#include "mbot/motion/pose2d.hpp"

namespace mbot::mapping {

struct MapperOptions {
  int hit_odds = 5;  // the seed report's choice (sharpest walls on the botlab logs)
  int miss_odds = 1;
  double resolution_m = 0.05;
  // Initial extent, centred on (center_x_m, center_y_m).
  double width_m = 10.0;
  double height_m = 10.0;
  double center_x_m = 0.0;
  double center_y_m = 0.0;
  bool grow = true;           // false: rays leaving the extent are clipped (never past kMaxGridCells)
  double grow_block_m = 5.0;  // the extent grows by multiples of this
  bool hit_moments = false;   // keep each cell's hit moments (ndt.hpp) beside the grid
  // Each hit adds to its cell's moments with the weight (its range / 1 m)^hit_range_power (ranges
  // under 0.1 m count as 0.1 m); 0: every hit alike. The robot's own hits from close by, taken
  // scan after scan, otherwise outweigh what it saw of the same wall from afar: the moments then
  // follow its last few poses, and a fit against them inherits each pose's error (ndt.hpp).
  double hit_range_power = 0.0;
};

class LogOddsMapper {
 public:
  explicit LogOddsMapper(const MapperOptions& options);
  // Starts from an existing map (its extent and resolution replace the options').
  void Reset(OccupancyGrid map);

  // Inserts rays given in the frame of `robot_pose` (see DeskewScan). Rays with a non-finite end are
  // dropped; a scan that would grow the grid past kMaxGridCells (a corrupt range or pose) is not
  // inserted and is counted in rejected_scans(). Returns whether the scan was inserted.
  bool Insert(const std::vector<ScanRay>& rays, const motion::Pose2D& robot_pose);

  const OccupancyGrid& map() const { return map_; }
  // The hits' moments per cell (options.hit_moments; empty otherwise). A map given to Reset starts
  // with none: its cells' hits are not known.
  const HitMoments& moments() const { return moments_; }
  int grow_count() const { return grow_count_; }
  int rejected_scans() const { return rejected_scans_; }

 private:
  bool EnsureCovers(double min_x, double min_y, double max_x, double max_y);
  void ResetMoments();  // options_.hit_moments: zero moments for map_ (refused past HitMoments::kMaxCells)
  double HitWeight(double range_m) const;  // a hit's weight in the moments (hit_range_power)

  MapperOptions options_;
  OccupancyGrid map_;
  HitMoments moments_;
  int grow_count_ = 0;
  int rejected_scans_ = 0;
};

// Cells on the segment between two cells, both ends included, in order (Bresenham).
void BresenhamLine(int x0, int y0, int x1, int y1, std::vector<int>* xs, std::vector<int>* ys);

}  // namespace mbot::mapping
