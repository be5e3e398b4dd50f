// Exact Euclidean distance transform: a pass down each column, then per row the lower envelope of
// parabolas over the squared column distances (Felzenszwalb & Huttenlocher 2012). The envelope is
// built in integer arithmetic, intersections kept as fractions and compared by cross-multiplying,
// so it needs no division and the squared distances are exact integers. Shared by the planner's
// obstacle-distance grid (incrementally) and the likelihood-field sensor model.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

namespace mbot::mapping {

// Cells [x0, x1] × [y0, y1], inclusive; empty when x1 < x0.
struct CellRect {
  int x0 = 0, y0 = 0, x1 = -1, y1 = -1;
  bool empty() const { return x1 < x0 || y1 < y0; }
  void Add(int x, int y);
  void Add(const CellRect& other);
};

// The transform of one obstacle mask, kept so that a changed mask is brought up to date by
// recomputing only what the change can reach: the columns the changed cells are in, then the rows
// whose column distances changed. The result is the same as a transform from scratch.
class EuclideanDistanceTransform {
 public:
  static constexpr int32_t kNoObstacle = std::numeric_limits<int32_t>::max();

  // From scratch: squared distance in cells² from every cell of the row-major width × height mask to
  // the nearest non-zero (obstacle) cell; kNoObstacle everywhere when there is none. Up to two
  // threads on large grids; the result does not depend on the thread count.
  void Compute(const uint8_t* obstacle, int width, int height);
  // The same mask size with some cells changed: returns the cells whose squared distance changed.
  // A different size computes from scratch (and returns the whole grid).
  CellRect Update(const uint8_t* obstacle, int width, int height);

  int width() const { return width_; }
  int height() const { return height_; }
  const std::vector<int32_t>& squared() const { return squared_; }

 private:
  void Columns(int x0, int x1, std::vector<uint8_t>* rows_changed);
  void Rows(const std::vector<uint8_t>* rows, CellRect* changed);

  int width_ = 0, height_ = 0;
  std::vector<uint8_t> mask_;
  std::vector<int32_t> column_;   // distance in cells to the nearest obstacle in the same column
  std::vector<int32_t> squared_;  // the result
};

// Squared distance in cells² from every cell of a row-major width × height mask to the nearest
// non-zero (obstacle) cell; +inf everywhere when there is no obstacle.
std::vector<float> SquaredDistanceTransform(const std::vector<uint8_t>& obstacle, int width, int height);

}  // namespace mbot::mapping
