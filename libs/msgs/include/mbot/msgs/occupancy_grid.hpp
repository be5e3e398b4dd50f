// The log-odds occupancy grid every module shares: int8 cells in [-127, 127] (>0 occupied, <0 free,
// 0 unknown), row-major with row 0 at the lowest y, cell (0,0)'s corner at the origin.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace mbot::msgs {

// The most cells a grid may have (a 16,384 × 16,384 grid, 256 MB of int8): map files, config keys
// and a growing map are all held to it.
inline constexpr long long kMaxGridCells = 1LL << 28;

class OccupancyGrid {
 public:
  OccupancyGrid() = default;
  // A width × height grid of `resolution_m` cells whose lower-left corner is (origin_x_m, origin_y_m),
  // every cell set to `fill`.
  OccupancyGrid(int width, int height, double resolution_m, double origin_x_m, double origin_y_m, int8_t fill = 0);

  int width() const { return width_; }
  int height() const { return height_; }
  double resolution() const { return resolution_; }
  double origin_x() const { return origin_x_; }
  double origin_y() const { return origin_y_; }

  bool IsInside(int cx, int cy) const { return cx >= 0 && cy >= 0 && cx < width_ && cy < height_; }
  int8_t at(int cx, int cy) const { return cells_[static_cast<size_t>(cy) * width_ + cx]; }
  int8_t& at(int cx, int cy) { return cells_[static_cast<size_t>(cy) * width_ + cx]; }
  const std::vector<int8_t>& cells() const { return cells_; }
  std::vector<int8_t>& cells() { return cells_; }

  // World (metres) → cell indices (floor); the result may lie outside the grid.
  void WorldToCell(double x, double y, int* cx, int* cy) const;
  // Centre of a cell in world coordinates.
  void CellToWorld(int cx, int cy, double* x, double* y) const;

  struct Stats {
    int occupied = 0;
    int free = 0;
    int unknown = 0;
  };
  Stats CountCells() const;

  bool operator==(const OccupancyGrid& o) const;

 private:
  int width_ = 0;
  int height_ = 0;
  double resolution_ = 0.05;
  double origin_x_ = 0.0;
  double origin_y_ = 0.0;
  std::vector<int8_t> cells_;
};

// The grid's known cells (non-zero) and `margin_m` around them, in the same frame; the grid itself
// when nothing is known. SLAM's map starts large; a picture of it need not.
OccupancyGrid CropToKnown(const OccupancyGrid& grid, double margin_m);

}  // namespace mbot::msgs
