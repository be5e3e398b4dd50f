// Exact Euclidean distance transform (Felzenszwalb & Huttenlocher's lower-envelope pass per column
// and row). Shared by the planner's obstacle-distance grid and the likelihood-field sensor model.
#pragma once

#include <cstdint>
#include <vector>

namespace mbot::mapping {

// Squared distance in cells² from every cell of a row-major width × height mask to the nearest
// non-zero (obstacle) cell; +inf everywhere when there is no obstacle. Uses up to two threads on
// large grids; the result does not depend on the thread count.
std::vector<float> SquaredDistanceTransform(const std::vector<uint8_t>& obstacle, int width, int height);

}  // namespace mbot::mapping
