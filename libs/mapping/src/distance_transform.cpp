#include "mbot/mapping/distance_transform.hpp"

#include <algorithm>
#include <cstring>

namespace mbot::mapping {
namespace {

constexpr int32_t kFar = 1 << 29;  // column distance where the column has no obstacle
constexpr size_t kThreadedCells = 100000;

// One row of the envelope pass. col[q] is the column distance at q (kFar: none); writes the
// squared distances to out. v, num, den are scratch of size n + 1: the envelope's parabolas and
// the left ends of their intervals as fractions num / den (den > 0).
void EnvelopeRow(const int32_t* col, int n, int32_t* out, int* v, int64_t* lift, int64_t* num, int64_t* den) {
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (col[q] >= kFar) continue;  // no obstacle in this column: no parabola
    const int64_t c = col[q];
    const int64_t fq = c * c + int64_t{q} * q;  // f(q) + q², with f the squared column distance
    if (k < 0) {
      k = 0;
      v[0] = q;
      lift[0] = fq;
      continue;
    }
    // Intersection with the parabola of v[k]: s = (fq − f(p) − p²) / (2 (q − p)). Drop parabolas
    // whose interval starts at or after it (the first one's starts at −∞, so it always stays).
    int64_t s_num, s_den;
    while (true) {
      s_num = fq - lift[k];
      s_den = 2 * int64_t{q - v[k]};
      if (k == 0 || s_num * den[k] > num[k] * s_den) break;
      --k;
    }
    ++k;
    v[k] = q;
    lift[k] = fq;
    num[k] = s_num;
    den[k] = s_den;
  }
  if (k < 0) {
    std::fill(out, out + n, EuclideanDistanceTransform::kNoObstacle);
    return;
  }
  int j = 0;
  for (int q = 0; q < n; ++q) {
    while (j < k && num[j + 1] < int64_t{q} * den[j + 1]) ++j;  // interval of j + 1 starts before q
    const int64_t dq = q - v[j];
    out[q] = static_cast<int32_t>(dq * dq + lift[j] - int64_t{v[j]} * v[j]);
  }
}

}  // namespace

void CellRect::Add(int x, int y) {
  if (empty()) {
    x0 = x1 = x;
    y0 = y1 = y;
    return;
  }
  x0 = std::min(x0, x), x1 = std::max(x1, x);
  y0 = std::min(y0, y), y1 = std::max(y1, y);
}

void CellRect::Add(const CellRect& o) {
  if (o.empty()) return;
  Add(o.x0, o.y0);
  Add(o.x1, o.y1);
}

// Column distances of columns [x0, x1], one sweep down and one up, both walking rows in order (so
// they vectorise). From scratch (rows_changed null) threads take blocks of columns and sweep in
// place; an update sweeps a scratch copy and marks the rows where a value changed.
void EuclideanDistanceTransform::Columns(int x0, int x1, std::vector<uint8_t>* rows_changed) {
  constexpr int kBlock = 256;
  const int w = width_, h = height_;
  const int blocks = (x1 - x0 + kBlock) / kBlock;
  if (!rows_changed) {
#pragma omp parallel for schedule(static) if (static_cast <size_t>(x1 - x0 + 1) * h > kThreadedCells)
    for (int b = 0; b < blocks; ++b) {
      const int bx0 = x0 + b * kBlock, bx1 = std::min(x1 + 1, bx0 + kBlock);
      for (int x = bx0; x < bx1; ++x) column_[x] = mask_[x] ? 0 : kFar;
      for (int y = 1; y < h; ++y) {
        const uint8_t* o = &mask_[static_cast<size_t>(y) * w];
        const int32_t* above = &column_[static_cast<size_t>(y - 1) * w];
        int32_t* cur = &column_[static_cast<size_t>(y) * w];
        for (int x = bx0; x < bx1; ++x) cur[x] = o[x] ? 0 : std::min(above[x] + 1, kFar);
      }
      for (int y = h - 2; y >= 0; --y) {
        const int32_t* below = &column_[static_cast<size_t>(y + 1) * w];
        int32_t* cur = &column_[static_cast<size_t>(y) * w];
        for (int x = bx0; x < bx1; ++x) cur[x] = std::min(cur[x], below[x] + 1);
      }
    }
    return;
  }
  const int n = x1 - x0 + 1;
  std::vector<int32_t> sweep(static_cast<size_t>(n) * h);
  for (int y = 0; y < h; ++y) {
    const uint8_t* o = &mask_[static_cast<size_t>(y) * w + x0];
    int32_t* s = &sweep[static_cast<size_t>(y) * n];
    if (y == 0) {
      for (int i = 0; i < n; ++i) s[i] = o[i] ? 0 : kFar;
      continue;
    }
    const int32_t* above = s - n;
    for (int i = 0; i < n; ++i) s[i] = o[i] ? 0 : std::min(above[i] + 1, kFar);
  }
  for (int y = h - 1; y >= 0; --y) {
    int32_t* s = &sweep[static_cast<size_t>(y) * n];
    if (y + 1 < h) {
      const int32_t* below = s + n;
      for (int i = 0; i < n; ++i) s[i] = std::min(s[i], below[i] + 1);
    }
    int32_t* c = &column_[static_cast<size_t>(y) * w + x0];
    if (std::memcmp(c, s, sizeof(int32_t) * n) != 0) {
      (*rows_changed)[y] = 1;
      std::copy_n(s, n, c);
    }
  }
}

void EuclideanDistanceTransform::Rows(const std::vector<uint8_t>* rows, CellRect* changed) {
  const int w = width_, h = height_;
  const bool threaded = static_cast<size_t>(w) * h > kThreadedCells;
#pragma omp parallel if (threaded)
  {
    std::vector<int> v(w + 1);
    std::vector<int64_t> lift(w + 1), num(w + 1), den(w + 1);
    std::vector<int32_t> out(changed ? w : 0);
    CellRect mine;
#pragma omp for schedule(dynamic, 16)
    for (int y = 0; y < h; ++y) {
      if (rows && !(*rows)[y]) continue;
      int32_t* row = &squared_[static_cast<size_t>(y) * w];
      const int32_t* col = &column_[static_cast<size_t>(y) * w];
      if (!changed) {
        EnvelopeRow(col, w, row, v.data(), lift.data(), num.data(), den.data());
        continue;
      }
      EnvelopeRow(col, w, out.data(), v.data(), lift.data(), num.data(), den.data());
      int first = -1, last = -1;
      for (int x = 0; x < w; ++x) {
        if (out[x] != row[x]) {
          if (first < 0) first = x;
          last = x;
        }
      }
      if (first >= 0) {
        mine.Add(first, y);
        mine.Add(last, y);
        std::copy_n(out.data(), w, row);
      }
    }
    if (changed) {
#pragma omp critical
      changed->Add(mine);
    }
  }
}

void EuclideanDistanceTransform::Compute(const uint8_t* obstacle, int width, int height) {
  width_ = width;
  height_ = height;
  const size_t n = static_cast<size_t>(width) * height;
  mask_.assign(obstacle, obstacle + n);
  column_.resize(n);  // every value is written
  squared_.resize(n);
  if (n == 0) return;
  Columns(0, width - 1, nullptr);
  Rows(nullptr, nullptr);
}

CellRect EuclideanDistanceTransform::Update(const uint8_t* obstacle, int width, int height) {
  CellRect changed;
  if (width != width_ || height != height_ || mask_.empty()) {
    Compute(obstacle, width, height);
    if (width > 0 && height > 0) changed = {0, 0, width - 1, height - 1};
    return changed;
  }
  // The columns holding a changed cell: only their column distances can change.
  int x0 = width, x1 = -1;
  for (int y = 0; y < height; ++y) {
    const uint8_t* a = &mask_[static_cast<size_t>(y) * width];
    const uint8_t* b = obstacle + static_cast<size_t>(y) * width;
    if (std::memcmp(a, b, width) == 0) continue;
    for (int x = 0; x < width; ++x) {
      if (a[x] != b[x]) {
        x0 = std::min(x0, x);
        x1 = std::max(x1, x);
      }
    }
  }
  if (x1 < 0) return changed;
  std::copy_n(obstacle, mask_.size(), mask_.begin());
  std::vector<uint8_t> rows(height, 0);
  Columns(x0, x1, &rows);
  Rows(&rows, &changed);
  return changed;
}

std::vector<float> SquaredDistanceTransform(const std::vector<uint8_t>& obstacle, int width, int height) {
  EuclideanDistanceTransform t;
  t.Compute(obstacle.data(), width, height);
  std::vector<float> out(t.squared().size());
  constexpr float kInf = std::numeric_limits<float>::infinity();
  for (size_t i = 0; i < out.size(); ++i) {
    const int32_t s = t.squared()[i];
    out[i] = s == EuclideanDistanceTransform::kNoObstacle ? kInf : static_cast<float>(s);
  }
  return out;
}

}  // namespace mbot::mapping
