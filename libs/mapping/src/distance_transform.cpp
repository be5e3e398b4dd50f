#include "mbot/mapping/distance_transform.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mbot::mapping {
namespace {

// One-dimensional squared distance transform of a sampled function f (Felzenszwalb & Huttenlocher
// 2012): d[q] = min_p (q - p)² + f[p]. v, z are scratch buffers of size n and n + 1.
void Transform1D(const float* f, int n, float* d, int* v, float* z) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (f[q] == kInf) continue;  // sample with no obstacle behind it: contributes no parabola
    if (k < 0) {
      k = 0;
      v[0] = q;
      z[0] = -kInf;
      z[1] = kInf;
      continue;
    }
    float s;
    while (true) {  // z[0] = -inf, so this stops at k = 0 at the latest
      const int p = v[k];
      s = static_cast<float>(((double(f[q]) + double(q) * q) - (double(f[p]) + double(p) * p)) / (2.0 * (q - p)));
      if (s > z[k]) break;
      --k;
    }
    ++k;
    v[k] = q;
    z[k] = s;
    z[k + 1] = kInf;
  }
  if (k < 0) {
    for (int q = 0; q < n; ++q) d[q] = kInf;
    return;
  }
  int j = 0;
  for (int q = 0; q < n; ++q) {
    while (z[j + 1] < q) ++j;
    const float dq = float(q - v[j]);
    d[q] = dq * dq + f[v[j]];
  }
}

}  // namespace

std::vector<float> SquaredDistanceTransform(const std::vector<uint8_t>& obstacle, int width, int height) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  std::vector<float> out(static_cast<size_t>(width) * height);
  // Pass 1, along columns: distance in cells to the nearest obstacle in the same column, by one
  // sweep up and one down. Both sweeps walk rows in order (and vectorise); threads take column blocks.
  std::vector<int32_t> col(static_cast<size_t>(width) * height);
  constexpr int32_t kFar = 1 << 29;
  constexpr int kBlock = 256;
  const int blocks = (width + kBlock - 1) / kBlock;
#pragma omp parallel for schedule(static) if (static_cast <size_t>(width) * height > 100000)
  for (int b = 0; b < blocks; ++b) {
    const int x0 = b * kBlock, x1 = std::min(width, x0 + kBlock);
    for (int x = x0; x < x1; ++x) col[x] = obstacle[x] ? 0 : kFar;
    for (int y = 1; y < height; ++y) {
      const uint8_t* o = &obstacle[static_cast<size_t>(y) * width];
      const int32_t* prev = &col[static_cast<size_t>(y - 1) * width];
      int32_t* cur = &col[static_cast<size_t>(y) * width];
      for (int x = x0; x < x1; ++x) cur[x] = o[x] ? 0 : std::min(prev[x] + 1, kFar);
    }
    for (int y = height - 2; y >= 0; --y) {
      const int32_t* next = &col[static_cast<size_t>(y + 1) * width];
      int32_t* cur = &col[static_cast<size_t>(y) * width];
      for (int x = x0; x < x1; ++x) cur[x] = std::min(cur[x], next[x] + 1);
    }
  }
  // Pass 2, along rows: the lower envelope of parabolas over the squared column distances. Rows
  // are independent; each thread keeps its own scratch. The result does not depend on the threads.
#pragma omp parallel if (static_cast <size_t>(width) * height > 100000)
  {
    std::vector<float> f(width), z(width + 1);
    std::vector<int> v(width);
#pragma omp for schedule(static)
    for (int y = 0; y < height; ++y) {
      const int32_t* c = &col[static_cast<size_t>(y) * width];
      for (int x = 0; x < width; ++x) f[x] = c[x] >= kFar ? kInf : float(c[x]) * float(c[x]);
      Transform1D(f.data(), width, &out[static_cast<size_t>(y) * width], v.data(), z.data());
    }
  }
  return out;
}

}  // namespace mbot::mapping
