// Jump point search (Harabor & Grastien 2011) for the planner's uniform-cost queries: 8-connected,
// octile costs, no diagonal step past an obstacle corner (the Moving AI rules). Straight scans read
// 64 cells at a time from bit rows (Harabor & Grastien 2014's block-based jumps); vertical and
// backward scans read transposed and mirrored copies, so every scan is the same forward one.
// Private to mbot_planning: AStarPlanner owns the node array and the open list it searches with.
#pragma once

#include <cstddef>
#include <algorithm>
#include <cstdint>
#include <vector>

namespace mbot::planning::detail {

// One cell's search state; mark is 2·generation while open (g valid), 2·generation + 1 once closed.
struct SearchNode {
  double g;
  int32_t parent;
  uint32_t mark;
};

// Open/closed marks of one byte per cell, reset in O(1) by a generation count (cleared once
// every 127 searches). A byte per cell keeps the marks of a 1000 × 1000 grid within 1 MB, so the
// far-apart cells a jump point search touches are checked from cache.
class SearchMarks {
 public:
  void Resize(size_t cells) {
    marks_.assign(cells, 0);
    generation_ = 0;
  }
  void Next() {
    if (++generation_ > 127) {
      std::fill(marks_.begin(), marks_.end(), uint8_t{0});
      generation_ = 1;
    }
  }
  uint8_t open() const { return static_cast<uint8_t>(2 * generation_); }
  uint8_t closed() const { return static_cast<uint8_t>(2 * generation_ + 1); }
  uint8_t* data() { return marks_.data(); }

 private:
  std::vector<uint8_t> marks_;
  unsigned generation_ = 0;
};

// The open list both searches use: a binary heap of (f, node, g) — smallest f first and among
// equal f the deeper node (larger g), which keeps a search from fanning out over the many
// equal-cost paths of an open grid — and a stack for successors whose f equals the f being expanded:
// those are minimal already and are expanded next without touching the heap (on open grids most
// successors are such). A node may be in it more than once; the search skips stale entries. A
// 4-ary heap was measured slower here than std::pop_heap's sift of the hole to the bottom.
class OpenList {
 public:
  void Clear() {
    heap_.clear();
    fast_.clear();
  }
  bool Empty() const { return fast_.empty() && heap_.empty(); }
  // `node` reached with cost g and estimate f while expanding a node whose f is f_expanding
  // (+inf for the start).
  void Push(int32_t node, double f, double g, double f_expanding) {
    if (f <= f_expanding + 1e-9) {
      fast_.push_back(node);
    } else {
      heap_.push_back({f, node, static_cast<float>(g)});
      std::push_heap(heap_.begin(), heap_.end(), Order{});
    }
  }
  int32_t Pop() {
    if (!fast_.empty()) {
      const int32_t n = fast_.back();
      fast_.pop_back();
      return n;
    }
    std::pop_heap(heap_.begin(), heap_.end(), Order{});
    const int32_t n = heap_.back().index;
    heap_.pop_back();
    return n;
  }

 private:
  struct Entry {  // 16 bytes: g as float, only to break ties
    double f;
    int32_t index;
    float g;
  };
  struct Order {
    bool operator()(const Entry& a, const Entry& b) const { return a.f > b.f || (a.f == b.f && a.g < b.g); }
  };
  std::vector<Entry> heap_;
  std::vector<int32_t> fast_;
};

// The cells passable at one clearance (obstacle distance > clearance) of a padded grid (a border of
// impassable cells all round; index = y · stride + x), as bit rows: by row and by column, each also
// mirrored.
class PassableBits {
 public:
  PassableBits(const std::vector<float>& dist, int stride, int rows, float clearance);

  float clearance() const { return clearance_; }
  bool Open(int x, int y) const { return (Word(row_, row_words_, y, x >> 6) >> (x & 63)) & 1u; }

  // The first jump point from (x, y) stepping by (dx, dy) (one of the eight moves), or -1 when the
  // scan runs into an obstacle (or, diagonally, past a corner) first. The goal is a padded cell.
  int Jump(int x, int y, int dx, int dy, int goal_x, int goal_y) const;

 private:
  static uint64_t Word(const std::vector<uint64_t>& bits, int words, int line, int w) {
    return bits[static_cast<size_t>(line) * words + w];
  }
  // The first jump point along one line at a position after `pos`, or -1: `line` holds the cells
  // scanned, `side_a`/`side_b` the lines beside it.
  static int Scan(const uint64_t* line, const uint64_t* side_a, const uint64_t* side_b, int pos, int goal_pos);
  int JumpStraight(int x, int y, int dx, int dy, int goal_x, int goal_y) const;

  int stride_, rows_;
  float clearance_;
  int row_words_, col_words_;
  std::vector<uint64_t> row_, row_mirror_, col_, col_mirror_;
};

// Jump point search from `start` to `goal` (padded indices) on `bits`, with the caller's marks,
// node array (g and parent; its marks unused) and open list. Each node's parent is the previous
// jump point.
// Returns true when the goal was closed; adds the nodes expanded to *expansions.
bool JumpPointSearch(const PassableBits& bits, int stride, int start, int goal, SearchMarks& marks,
                     std::vector<SearchNode>& nodes, OpenList& open, int64_t budget, int64_t* expansions,
                     bool* budget_hit);

}  // namespace mbot::planning::detail
