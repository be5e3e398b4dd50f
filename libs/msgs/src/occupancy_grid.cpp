#include "mbot/msgs/occupancy_grid.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace mbot::msgs {

OccupancyGrid::OccupancyGrid(int width, int height, double resolution_m, double origin_x_m, double origin_y_m,
                             int8_t fill)
    : width_(width), height_(height), resolution_(resolution_m), origin_x_(origin_x_m), origin_y_(origin_y_m) {
  if (width < 0 || height < 0 || !(resolution_m > 0.0)) {
    throw std::invalid_argument("OccupancyGrid: bad size " + std::to_string(width) + "x" + std::to_string(height) +
                                " or resolution " + std::to_string(resolution_m));
  }
  cells_.assign(static_cast<size_t>(width) * height, fill);
}

void OccupancyGrid::WorldToCell(double x, double y, int* cx, int* cy) const {
  *cx = static_cast<int>(std::floor((x - origin_x_) / resolution_));
  *cy = static_cast<int>(std::floor((y - origin_y_) / resolution_));
}

void OccupancyGrid::CellToWorld(int cx, int cy, double* x, double* y) const {
  *x = origin_x_ + (cx + 0.5) * resolution_;
  *y = origin_y_ + (cy + 0.5) * resolution_;
}

OccupancyGrid::Stats OccupancyGrid::CountCells() const {
  Stats s;
  for (int8_t c : cells_) {
    if (c > 0)
      ++s.occupied;
    else if (c < 0)
      ++s.free;
    else
      ++s.unknown;
  }
  return s;
}

bool OccupancyGrid::operator==(const OccupancyGrid& o) const {
  return width_ == o.width_ && height_ == o.height_ && resolution_ == o.resolution_ && origin_x_ == o.origin_x_ &&
         origin_y_ == o.origin_y_ && cells_ == o.cells_;
}

OccupancyGrid CropToKnown(const OccupancyGrid& m, double margin_m) {
  int x0 = m.width(), y0 = m.height(), x1 = -1, y1 = -1;
  for (int cy = 0; cy < m.height(); ++cy) {
    for (int cx = 0; cx < m.width(); ++cx) {
      if (m.at(cx, cy) == 0) continue;
      x0 = std::min(x0, cx), x1 = std::max(x1, cx), y0 = std::min(y0, cy), y1 = std::max(y1, cy);
    }
  }
  if (x1 < 0) return m;
  const int pad = static_cast<int>(std::ceil(margin_m / m.resolution()));
  x0 = std::max(0, x0 - pad), y0 = std::max(0, y0 - pad);
  x1 = std::min(m.width() - 1, x1 + pad), y1 = std::min(m.height() - 1, y1 + pad);
  OccupancyGrid c(x1 - x0 + 1, y1 - y0 + 1, m.resolution(), m.origin_x() + x0 * m.resolution(),
                  m.origin_y() + y0 * m.resolution());
  for (int cy = y0; cy <= y1; ++cy) {
    for (int cx = x0; cx <= x1; ++cx) c.at(cx - x0, cy - y0) = m.at(cx, cy);
  }
  return c;
}

}  // namespace mbot::msgs
