#include "mbot/sim/maze_generator.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace mbot::sim {
namespace {

// SplitMix64: tiny, and the same numbers on every platform and standard library (the distributions
// of <random> are not), so a seed names the same maze everywhere.
class Rng {
 public:
  explicit Rng(uint64_t seed) : s_(seed * 0x9E3779B97F4A7C15ULL + 0x2545F4914F6CDD1DULL) {}
  uint64_t Next() {
    uint64_t z = (s_ += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  double Uniform() { return (Next() >> 11) * 0x1.0p-53; }  // [0, 1)
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  int Int(int lo, int hi) { return lo + static_cast<int>(Next() % static_cast<uint64_t>(hi - lo + 1)); }  // [lo, hi]

 private:
  uint64_t s_;
};

constexpr int kDx[4] = {1, 0, -1, 0};  // east, north, west, south
constexpr int kDy[4] = {0, 1, 0, -1};

// The wall between cell (x, y) and its neighbour in direction d.
uint8_t& WallToward(Maze& m, int x, int y, int d) {
  switch (d) {
    case 0: return m.vertical[static_cast<size_t>(x + 1) * m.rows + y];
    case 1: return m.horizontal[static_cast<size_t>(y + 1) * m.cols + x];
    case 2: return m.vertical[static_cast<size_t>(x) * m.rows + y];
    default: return m.horizontal[static_cast<size_t>(y) * m.cols + x];
  }
}

bool Open(const Maze& m, int x, int y, int d) { return !WallToward(const_cast<Maze&>(m), x, y, d); }

std::string Num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3f", v);
  std::string s = b;
  if (s == "-0.000") s = "0.000";
  return s;
}

}  // namespace

void CheckMazeStyle(const MazeStyle& s) {
  auto range = [](const char* name, double lo, double hi, double min, double max) {
    if (!(lo >= min && hi <= max && lo <= hi)) {
      throw std::invalid_argument(std::string("maze style: ") + name + " range [" + Num(lo) + ", " + Num(hi) +
                                  "] must lie within [" + Num(min) + ", " + Num(max) + "] with min <= max");
    }
  };
  range("cols", s.min_cols, s.max_cols, 2, 32);
  range("rows", s.min_rows, s.max_rows, 2, 32);
  range("straightness", s.min_straightness, s.max_straightness, 0, 1);
  range("openings", s.min_openings, s.max_openings, 0, 1);
  range("rooms", s.min_rooms, s.max_rooms, 0, 16);
  if (!(s.cell_m > 0) || !(s.thickness_m > 0) || !(s.thickness_m < s.cell_m / 2) || !(s.resolution_m > 0)) {
    throw std::invalid_argument(
        "maze style: cell_m, thickness_m and resolution_m must be positive, thickness_m "
        "below half a cell");
  }
}

Maze GenerateMaze(const MazeStyle& style, uint64_t seed) {
  CheckMazeStyle(style);
  Rng rng(seed);
  Maze m;
  m.seed = seed;
  m.cols = rng.Int(style.min_cols, style.max_cols);
  m.rows = rng.Int(style.min_rows, style.max_rows);
  m.cell_m = style.cell_m, m.thickness_m = style.thickness_m, m.resolution_m = style.resolution_m;
  m.straightness = rng.Uniform(style.min_straightness, style.max_straightness);
  const double openings_share = rng.Uniform(style.min_openings, style.max_openings);
  const int rooms = rng.Int(style.min_rooms, style.max_rooms);
  m.horizontal.assign(static_cast<size_t>(m.rows + 1) * m.cols, 1);
  m.vertical.assign(static_cast<size_t>(m.cols + 1) * m.rows, 1);

  // Depth-first carving from the start cell: every cell joined by exactly one path (a perfect maze,
  // dead ends where the search backed up); keeping the last direction makes long corridors.
  std::vector<uint8_t> seen(static_cast<size_t>(m.cols) * m.rows, 0);
  struct Step {
    int x, y, dir;
  };
  std::vector<Step> stack = {{0, 0, -1}};
  seen[0] = 1;
  while (!stack.empty()) {
    const Step cur = stack.back();
    int options[4], n = 0;
    for (int d = 0; d < 4; ++d) {
      const int nx = cur.x + kDx[d], ny = cur.y + kDy[d];
      if (nx >= 0 && ny >= 0 && nx < m.cols && ny < m.rows && !seen[static_cast<size_t>(ny) * m.cols + nx])
        options[n++] = d;
    }
    if (n == 0) {
      stack.pop_back();
      continue;
    }
    int d = options[rng.Int(0, n - 1)];
    if (cur.dir >= 0 && std::find(options, options + n, cur.dir) != options + n && rng.Uniform() < m.straightness)
      d = cur.dir;
    WallToward(m, cur.x, cur.y, d) = 0;
    const int nx = cur.x + kDx[d], ny = cur.y + kDy[d];
    seen[static_cast<size_t>(ny) * m.cols + nx] = 1;
    stack.push_back({nx, ny, d});
  }

  // Open rooms: a block of cells with every wall inside it removed.
  for (int r = 0; r < rooms; ++r) {
    const bool wide = m.cols >= 6 && rng.Uniform() < 0.5;
    const int w = wide ? 3 : 2, h = 2;
    if (w > m.cols || h > m.rows) break;
    const int x0 = rng.Int(0, m.cols - w), y0 = rng.Int(0, m.rows - h);
    for (int y = y0; y < y0 + h; ++y) {
      for (int x = x0; x < x0 + w; ++x) {
        if (x + 1 < x0 + w) WallToward(m, x, y, 0) = 0;
        if (y + 1 < y0 + h) WallToward(m, x, y, 1) = 0;
      }
    }
    ++m.rooms;
  }

  // Extra openings: inner walls still standing, a share of them taken out (loops).
  std::vector<std::pair<int, int>> inner;  // (cell index, direction east or north)
  for (int y = 0; y < m.rows; ++y) {
    for (int x = 0; x < m.cols; ++x) {
      if (x + 1 < m.cols && !Open(m, x, y, 0)) inner.push_back({y * m.cols + x, 0});
      if (y + 1 < m.rows && !Open(m, x, y, 1)) inner.push_back({y * m.cols + x, 1});
    }
  }
  const int remove = static_cast<int>(std::lround(openings_share * inner.size()));
  for (int k = 0; k < remove; ++k) {
    const int pick = rng.Int(k, static_cast<int>(inner.size()) - 1);
    std::swap(inner[k], inner[pick]);
    WallToward(m, inner[k].first % m.cols, inner[k].first / m.cols, inner[k].second) = 0;
    ++m.openings;
  }

  for (int d : {0, 1, 2, 3}) {  // face the first way out of the start cell
    if (Open(m, 0, 0, d)) {
      m.start_theta_deg = 90.0 * d;
      break;
    }
  }
  return m;
}

int Maze::DeadEnds() const {
  int n = 0;
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      int walls = 0;
      for (int d = 0; d < 4; ++d) walls += !Open(*this, x, y, d);
      n += walls == 3;
    }
  }
  return n;
}

int Maze::LongestCorridor() const {
  int best = 1;
  for (int y = 0; y < rows; ++y) {
    for (int run = 1, x = 1; x < cols; ++x) {
      run = Open(*this, x - 1, y, 0) ? run + 1 : 1;
      best = std::max(best, run);
    }
  }
  for (int x = 0; x < cols; ++x) {
    for (int run = 1, y = 1; y < rows; ++y) {
      run = Open(*this, x, y - 1, 1) ? run + 1 : 1;
      best = std::max(best, run);
    }
  }
  return best;
}

int Maze::Loops() const {
  int passages = 0;
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x)
      passages += (x + 1 < cols && Open(*this, x, y, 0)) + (y + 1 < rows && Open(*this, x, y, 1));
  }
  return passages - (cols * rows - 1);
}

std::string Maze::Drawing() const {
  std::ostringstream out;
  for (int j = rows; j >= 0; --j) {
    for (int i = 0; i < cols; ++i) out << '+' << (HWall(i, j) ? "--" : "  ");
    out << "+\n";
    if (j == 0) break;
    const int y = j - 1;
    for (int i = 0; i <= cols; ++i) {
      out << (VWall(i, y) ? '|' : ' ');
      if (i < cols) out << (i == 0 && y == 0 ? "S " : "  ");
    }
    out << '\n';
  }
  return out.str();
}

std::string Maze::ToArena() const {
  std::ostringstream out;
  char head[256];
  std::snprintf(head, sizeof head,
                "# A generated botlab-style maze: seed %llu, %d x %d cells of %s m (panels %s m thick), "
                "straightness %.2f,\n# %d open room(s), %d extra opening(s): %d loop(s), %d dead end(s), "
                "longest corridor %d cells.\n",
                static_cast<unsigned long long>(seed), cols, rows, Num(cell_m).c_str(), Num(thickness_m).c_str(),
                straightness, rooms, openings, Loops(), DeadEnds(), LongestCorridor());
  out << head << "# The start cell's centre is the origin; x to the right, y up, as drawn (S = start):\n";
  std::istringstream drawing(Drawing());
  for (std::string line; std::getline(drawing, line);) out << "#   " << line << '\n';
  out << "name generated maze " << seed << " (" << cols << "x" << rows << " cells)\n";
  out << "resolution " << Num(resolution_m) << "\nthickness " << Num(thickness_m) << '\n';
  const double h = cell_m / 2;
  auto emit = [&](double x0, double y0, double x1, double y1) {
    out << "wall " << Num(x0) << ' ' << Num(y0) << ' ' << Num(x1) << ' ' << Num(y1) << '\n';
  };
  // Panels merged into straight walls: each maximal run of panels [a, b) along a line is one wall.
  auto runs = [](int n, auto wall, auto emit_run) {
    for (int a = 0; a < n;) {
      if (!wall(a)) {
        ++a;
        continue;
      }
      int b = a;
      while (b < n && wall(b)) ++b;
      emit_run(a, b);
      a = b;
    }
  };
  for (int j = 0; j <= rows; ++j) {  // horizontal lines
    runs(
        cols, [&](int i) { return HWall(i, j); },
        [&](int a, int b) { emit(a * cell_m - h, j * cell_m - h, b * cell_m - h, j * cell_m - h); });
  }
  for (int i = 0; i <= cols; ++i) {  // vertical lines
    runs(
        rows, [&](int j) { return VWall(i, j); },
        [&](int a, int b) { emit(i * cell_m - h, a * cell_m - h, i * cell_m - h, b * cell_m - h); });
  }
  out << "pose start 0 0 " << Num(start_theta_deg) << '\n';
  return out.str();
}

}  // namespace mbot::sim
