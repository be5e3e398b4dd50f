#include "jump_point_search.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

namespace mbot::planning::detail {
namespace {

constexpr double kSqrt2 = 1.4142135623730951;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// 64 cells from bit `pos` on (bit i = cell pos + i). The arrays carry two spare words at the end.
inline uint64_t BitsAt(const uint64_t* line, int pos) {
  const int w = pos >> 6, s = pos & 63;
  return s == 0 ? line[w] : (line[w] >> s) | (line[w + 1] << (64 - s));
}

inline int FirstSet(uint64_t bits) { return bits ? __builtin_ctzll(bits) : 64; }

inline double Octile(int dx, int dy) {
  dx = std::abs(dx);
  dy = std::abs(dy);
  return dx > dy ? dx + (kSqrt2 - 1.0) * dy : dy + (kSqrt2 - 1.0) * dx;
}

inline int Sign(int v) { return (v > 0) - (v < 0); }

}  // namespace

PassableBits::PassableBits(const std::vector<float>& dist, int stride, int rows, float clearance)
    : stride_(stride),
      rows_(rows),
      clearance_(clearance),
      row_words_((stride + 63) / 64 + 2),
      col_words_((rows + 63) / 64 + 2),
      row_(static_cast<size_t>(rows) * row_words_, 0),
      row_mirror_(row_.size(), 0),
      col_(static_cast<size_t>(stride) * col_words_, 0),
      col_mirror_(col_.size(), 0) {
  auto set = [](std::vector<uint64_t>& bits, int words, int line, int pos) {
    bits[static_cast<size_t>(line) * words + (pos >> 6)] |= uint64_t{1} << (pos & 63);
  };
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < stride; ++x) {
      if (!(dist[static_cast<size_t>(y) * stride + x] > clearance)) continue;
      set(row_, row_words_, y, x);
      set(row_mirror_, row_words_, y, stride - 1 - x);
      set(col_, col_words_, x, y);
      set(col_mirror_, col_words_, x, rows - 1 - y);
    }
  }
}

// Moving forward along `line` from `pos`, a cell c is a jump point when it is the goal or has a
// forced neighbour: a side cell that is open while the side cell behind c (beside c − 1) is
// blocked, so no path from c − 1 reaches it as cheaply without passing c. The scan ends at the
// first blocked cell (no jump point). The grid's blocked border ends every scan.
int PassableBits::Scan(const uint64_t* line, const uint64_t* side_a, const uint64_t* side_b, int pos, int goal_pos) {
  for (int c = pos + 1;; c += 64) {
    const uint64_t open = BitsAt(line, c);
    const uint64_t a = BitsAt(side_a, c), a_behind = BitsAt(side_a, c - 1);
    const uint64_t b = BitsAt(side_b, c), b_behind = BitsAt(side_b, c - 1);
    uint64_t stop = ((a & ~a_behind) | (b & ~b_behind)) & open;
    if (goal_pos >= c && goal_pos - c < 64) stop |= uint64_t{1} << (goal_pos - c);
    const int blocked = FirstSet(~open), found = FirstSet(stop);
    if (found < blocked) return c + found;
    if (blocked < 64) return -1;
  }
}

int PassableBits::JumpStraight(int x, int y, int dx, int dy, int goal_x, int goal_y) const {
  const uint64_t* r = row_.data();
  const uint64_t* rm = row_mirror_.data();
  const uint64_t* c = col_.data();
  const uint64_t* cm = col_mirror_.data();
  const size_t rw = row_words_, cw = col_words_;
  if (dx > 0) {
    const int p = Scan(r + y * rw, r + (y + 1) * rw, r + (y - 1) * rw, x, goal_y == y ? goal_x : -1);
    return p < 0 ? -1 : y * stride_ + p;
  }
  if (dx < 0) {
    const int m = stride_ - 1;
    const int p = Scan(rm + y * rw, rm + (y + 1) * rw, rm + (y - 1) * rw, m - x, goal_y == y ? m - goal_x : -1);
    return p < 0 ? -1 : y * stride_ + (m - p);
  }
  if (dy > 0) {
    const int p = Scan(c + x * cw, c + (x + 1) * cw, c + (x - 1) * cw, y, goal_x == x ? goal_y : -1);
    return p < 0 ? -1 : p * stride_ + x;
  }
  const int m = rows_ - 1;
  const int p = Scan(cm + x * cw, cm + (x + 1) * cw, cm + (x - 1) * cw, m - y, goal_x == x ? m - goal_y : -1);
  return p < 0 ? -1 : (m - p) * stride_ + x;
}

// Diagonally, a cell is a jump point when it is the goal or when either straight scan from it
// (along the two components of the move) finds one. With corner cutting ruled out, diagonal
// moves have no forced neighbours.
int PassableBits::Jump(int x, int y, int dx, int dy, int goal_x, int goal_y) const {
  const int goal = goal_y * stride_ + goal_x;
  if (dx == 0 || dy == 0) return JumpStraight(x, y, dx, dy, goal_x, goal_y);
  while (true) {
    if (!Open(x + dx, y) || !Open(x, y + dy) || !Open(x + dx, y + dy)) return -1;
    x += dx;
    y += dy;
    const int here = y * stride_ + x;
    if (here == goal || JumpStraight(x, y, dx, 0, goal_x, goal_y) >= 0 ||
        JumpStraight(x, y, 0, dy, goal_x, goal_y) >= 0) {
      return here;
    }
  }
}

bool JumpPointSearch(const PassableBits& bits, int stride, int start, int goal, SearchMarks& marks,
                     std::vector<SearchNode>& nodes, OpenList& open, int64_t budget, int64_t* expansions,
                     bool* budget_hit) {
  marks.Next();
  uint8_t* mark = marks.data();
  const uint8_t open_mark = marks.open(), closed_mark = marks.closed();
  const int gx = goal % stride, gy = goal / stride;
  auto h = [&](int x, int y) { return Octile(x - gx, y - gy); };
  open.Clear();
  nodes[start] = SearchNode{0.0, -1, 0};
  mark[start] = open_mark;
  open.Push(start, h(start % stride, start / stride), 0.0, kInfinity);
  int64_t expanded = 0;
  int dirs[8][2];
  while (!open.Empty()) {
    const int cur = open.Pop();
    if (mark[cur] == closed_mark) continue;  // stale duplicate of a node already expanded
    mark[cur] = closed_mark;
    const SearchNode& node = nodes[cur];
    if (cur == goal) {
      *expansions += expanded;
      return true;
    }
    if (budget > 0 && expanded >= budget) {
      *budget_hit = true;
      break;
    }
    ++expanded;
    const double g_cur = node.g;
    const int cx = cur % stride, cy = cur / stride;
    const double f_cur = g_cur + h(cx, cy);
    // The directions worth scanning, given the move that reached this node (pruning rules).
    int n = 0;
    if (node.parent < 0) {
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          if (dx != 0 || dy != 0) dirs[n][0] = dx, dirs[n][1] = dy, ++n;
    } else {
      const int dx = Sign(cx - node.parent % stride), dy = Sign(cy - node.parent / stride);
      dirs[n][0] = dx, dirs[n][1] = dy, ++n;
      if (dx != 0 && dy != 0) {
        dirs[n][0] = dx, dirs[n][1] = 0, ++n;
        dirs[n][0] = 0, dirs[n][1] = dy, ++n;
      } else if (dx != 0) {
        for (int s : {1, -1}) {
          if (bits.Open(cx, cy + s) && !bits.Open(cx - dx, cy + s)) {
            dirs[n][0] = 0, dirs[n][1] = s, ++n;
            dirs[n][0] = dx, dirs[n][1] = s, ++n;
          }
        }
      } else {
        for (int s : {1, -1}) {
          if (bits.Open(cx + s, cy) && !bits.Open(cx + s, cy - dy)) {
            dirs[n][0] = s, dirs[n][1] = 0, ++n;
            dirs[n][0] = s, dirs[n][1] = dy, ++n;
          }
        }
      }
    }
    for (int k = 0; k < n; ++k) {
      const int next = bits.Jump(cx, cy, dirs[k][0], dirs[k][1], gx, gy);
      if (next < 0) continue;
      const uint8_t m = mark[next];
      if (m == closed_mark) continue;
      const int nx = next % stride, ny = next / stride;
      const double g = g_cur + Octile(nx - cx, ny - cy);
      SearchNode& nn = nodes[next];
      if (m == open_mark && g >= nn.g) continue;
      nn = SearchNode{g, cur, 0};
      mark[next] = open_mark;
      open.Push(next, g + h(nx, ny), g, f_cur);
    }
  }
  *expansions += expanded;
  return false;
}

}  // namespace mbot::planning::detail
