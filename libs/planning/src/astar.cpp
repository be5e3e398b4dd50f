#include "mbot/planning/astar.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include "jump_point_search.hpp"

namespace mbot::planning {
namespace {

constexpr double kSqrt2 = 1.4142135623730951;
constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

const char* ToString(PlanStatus s) {
  switch (s) {
    case PlanStatus::kFound: return "found";
    case PlanStatus::kStartOffMap: return "start off the map";
    case PlanStatus::kGoalOffMap: return "goal off the map";
    case PlanStatus::kStartInCollision: return "start in collision";
    case PlanStatus::kGoalInCollision: return "goal in collision";
    case PlanStatus::kUnreachable: return "unreachable";
    case PlanStatus::kBudgetExhausted: return "node budget exhausted";
  }
  return "?";
}

// The grid is stored with a one-cell border of "never passable" cells, so the inner loop needs no
// bounds checks: padded index = (cy + 1) * stride + (cx + 1).
struct AStarPlanner::Impl {
  int width = 0, height = 0, stride = 0, rows = 0;
  double resolution = 0.05, origin_x = 0.0, origin_y = 0.0;
  std::vector<float> dist;     // padded; -1 on the border
  std::vector<float> penalty;  // padded; extra cost per cell of travel into the cell
  bool use_penalty = false;
  int offsets[8];
  double step_len[8];

  using Node = detail::SearchNode;
  std::vector<Node> nodes;
  uint32_t generation = 0;
  detail::SearchMarks jps_marks;
  detail::OpenList open;

  // Connected components (4-connected, which is what 8-connected moves without corner cutting
  // reach) of the passable cells per clearance, computed on first use.
  struct Components {
    float clearance;
    std::vector<int32_t> label;  // padded; -1 where not passable
  };
  std::vector<Components> components;
  // Passable cells as bit rows per clearance, for jump point search; built on first use.
  std::vector<std::unique_ptr<detail::PassableBits>> passable;

  const detail::PassableBits& PassableAt(float clearance) {
    for (const auto& p : passable) {
      if (p->clearance() == clearance) return *p;
    }
    passable.push_back(std::make_unique<detail::PassableBits>(dist, stride, rows, clearance));
    return *passable.back();
  }

  int Index(int cx, int cy) const { return (cy + 1) * stride + (cx + 1); }
  void CellOf(int index, int* cx, int* cy) const {
    *cx = index % stride - 1;
    *cy = index / stride - 1;
  }
  bool ToCell(double x, double y, int* cx, int* cy) const {
    *cx = static_cast<int>(std::floor((x - origin_x) / resolution));
    *cy = static_cast<int>(std::floor((y - origin_y) / resolution));
    return *cx >= 0 && *cy >= 0 && *cx < width && *cy < height;
  }
  // Start and goal cells (padded indices), checked in order: on the map, then clearer than `limit`.
  // Returns false with the status to report.
  bool Endpoints(const motion::Pose2D& start, const motion::Pose2D& goal, float limit, int* s, int* g,
                 PlanStatus* status) const {
    if (width == 0) throw std::logic_error("AStarPlanner: Plan called before SetMap");
    int sx, sy, gx, gy;
    if (!ToCell(start.x, start.y, &sx, &sy)) return *status = PlanStatus::kStartOffMap, false;
    if (!ToCell(goal.x, goal.y, &gx, &gy)) return *status = PlanStatus::kGoalOffMap, false;
    *s = Index(sx, sy);
    *g = Index(gx, gy);
    if (!(dist[*s] > limit)) return *status = PlanStatus::kStartInCollision, false;
    if (!(dist[*g] > limit)) return *status = PlanStatus::kGoalInCollision, false;
    return true;
  }

  void NextGeneration() {
    if (generation >= 0x7fffffffu) {
      for (Node& n : nodes) n.mark = 0;
      generation = 0;
    }
    ++generation;
  }

  const std::vector<int32_t>& ComponentsAt(float clearance) {
    for (const Components& c : components) {
      if (c.clearance == clearance) return c.label;
    }
    Components c{clearance, std::vector<int32_t>(dist.size(), -1)};
    std::vector<int32_t> stack;
    int32_t next = 0;
    for (int i = 0; i < static_cast<int>(dist.size()); ++i) {
      if (c.label[i] != -1 || !(dist[i] > clearance)) continue;
      c.label[i] = next;
      stack.push_back(i);
      while (!stack.empty()) {
        const int j = stack.back();
        stack.pop_back();
        for (int k = 0; k < 4; ++k) {  // offsets 0..3 are the 4-neighbours
          const int n = j + offsets[k];
          if (c.label[n] == -1 && dist[n] > clearance) {
            c.label[n] = next;
            stack.push_back(n);
          }
        }
      }
      ++next;
    }
    components.push_back(std::move(c));
    return components.back().label;
  }

  // Whether a search at `clearance` can connect start to goal: the goal must be passable and in
  // the component of the start or of one of the start's passable neighbours (the start cell
  // itself is the robot's, so it may be closer to a wall than this rung asks).
  bool Connected(int start, int goal, float clearance) {
    if (!(dist[goal] > clearance)) return false;
    const std::vector<int32_t>& label = ComponentsAt(clearance);
    const int32_t target = label[goal];
    if (label[start] == target) return true;
    for (int k = 0; k < 8; ++k) {
      if (label[start + offsets[k]] == target && MoveAllowed(start, k, clearance)) return true;
    }
    return false;
  }

  bool MoveAllowed(int from, int k, float clearance) const {
    const int to = from + offsets[k];
    if (!(dist[to] > clearance)) return false;
    if (k < 4) return true;
    // Diagonal: both side cells must be passable (no corner cutting).
    return dist[from + side_a[k]] > clearance && dist[from + side_b[k]] > clearance;
  }
  int side_a[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  int side_b[8] = {0, 0, 0, 0, 0, 0, 0, 0};

  // One A* (or Dijkstra with goal = -1) search. Returns true when the goal was closed.
  bool Search(int start, int goal, float clearance, int64_t budget, int64_t* expansions, bool* budget_hit) {
    NextGeneration();
    const uint32_t open_mark = 2 * generation, closed_mark = 2 * generation + 1;
    const bool informed = goal >= 0;
    const int gx = informed ? goal % stride : 0, gy = informed ? goal / stride : 0;
    // Octile distance in cells from (x, y) to the goal.
    auto h = [&](int x, int y) {
      if (!informed) return 0.0;
      const int dx = std::abs(x - gx), dy = std::abs(y - gy);
      return dx > dy ? dx + (kSqrt2 - 1.0) * dy : dy + (kSqrt2 - 1.0) * dx;
    };
    open.Clear();
    nodes[start] = Node{0.0, -1, open_mark};
    open.Push(start, h(start % stride, start / stride), 0.0, kInf);
    int64_t expanded = 0;
    while (!open.Empty()) {
      const int cur = open.Pop();
      Node& node = nodes[cur];
      if (node.mark == closed_mark) continue;  // stale duplicate of a node already expanded
      node.mark = closed_mark;
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
      bool open4[4];
      for (int k = 0; k < 8; ++k) {
        const int n = cur + offsets[k];
        const bool passable = dist[n] > clearance;
        if (k < 4) {
          open4[k] = passable;
          if (!passable) continue;
        } else if (!passable || !open4[diag_side_x[k]] || !open4[diag_side_y[k]]) {
          continue;  // diagonal past an obstacle corner
        }
        Node& nn = nodes[n];
        if (nn.mark == closed_mark) continue;
        double step = step_len[k];
        if (use_penalty) step *= 1.0 + penalty[n];
        const double g = g_cur + step;
        if (nn.mark == open_mark && g >= nn.g) continue;
        nn = Node{g, cur, open_mark};
        open.Push(n, g + h(cx + dxs[k], cy + dys[k]), g, f_cur);
      }
    }
    *expansions += expanded;
    return false;
  }
  // For diagonal k (4..7): the indices (0..3) of its two side neighbours.
  int diag_side_x[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  int diag_side_y[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  int dxs[8] = {1, -1, 0, 0, 1, 1, -1, -1};
  int dys[8] = {0, 0, 1, -1, 1, -1, 1, -1};
};

AStarPlanner::AStarPlanner(const AStarOptions& options) : options_(options), impl_(std::make_unique<Impl>()) {
  if (!(options.robot_radius_m >= 0.0) || !(options.ease_start_m >= 0.0) || !(options.ease_step_m >= 0.0) ||
      !(options.ease_max_m >= 0.0) || !(options.penalty_range_m >= 0.0) || !(options.penalty_weight >= 0.0)) {
    throw std::invalid_argument("AStarOptions: radius, easing and penalty values must be >= 0");
  }
  if (options.search == SearchAlgorithm::kJumpPoint && options.penalty_weight > 0.0 && options.penalty_range_m > 0.0) {
    throw std::invalid_argument(
        "AStarOptions: jump point search needs uniform step costs (penalty_weight = 0 or penalty_range_m = 0)");
  }
}
AStarPlanner::~AStarPlanner() = default;
AStarPlanner::AStarPlanner(AStarPlanner&&) noexcept = default;
AStarPlanner& AStarPlanner::operator=(AStarPlanner&&) noexcept = default;

bool AStarPlanner::has_map() const { return impl_->width > 0; }

bool AStarPlanner::UsesJumpPoints() const {
  switch (options_.search) {
    case SearchAlgorithm::kAStar: return false;
    case SearchAlgorithm::kJumpPoint: return true;
    case SearchAlgorithm::kAuto: break;
  }
  return !(options_.penalty_weight > 0.0 && options_.penalty_range_m > 0.0);
}

void AStarPlanner::SetMap(const ObstacleDistanceGrid& d) {
  Impl& m = *impl_;
  m.width = d.width();
  m.height = d.height();
  m.stride = m.width + 2;
  m.rows = m.height + 2;
  m.resolution = d.resolution();
  m.origin_x = d.origin_x();
  m.origin_y = d.origin_y();
  const size_t n = static_cast<size_t>(m.stride) * m.rows;
  m.dist.assign(n, -1.0f);
  for (int y = 0; y < m.height; ++y) {
    std::copy_n(&d.distances()[static_cast<size_t>(y) * m.width], m.width, &m.dist[m.Index(0, y)]);
  }
  m.use_penalty = options_.penalty_weight > 0.0 && options_.penalty_range_m > 0.0;
  m.penalty.assign(m.use_penalty ? n : 0, 0.0f);
  if (m.use_penalty) {
    for (size_t i = 0; i < n; ++i) m.penalty[i] = PenaltyAt(m.dist[i]);
  }
  // 4-neighbours first (the component labelling uses offsets 0..3), then diagonals with their sides.
  const int s = m.stride;
  const int* dxs = m.dxs;
  const int* dys = m.dys;
  for (int k = 0; k < 8; ++k) {
    // Cardinal neighbours are 0: +x, 1: -x, 2: +y, 3: -y.
    m.diag_side_x[k] = dxs[k] > 0 ? 0 : 1;
    m.diag_side_y[k] = dys[k] > 0 ? 2 : 3;
    m.offsets[k] = dys[k] * s + dxs[k];
    m.step_len[k] = k < 4 ? 1.0 : kSqrt2;
    m.side_a[k] = k < 4 ? 0 : dxs[k];
    m.side_b[k] = k < 4 ? 0 : dys[k] * s;
  }
  if (m.nodes.size() != n) {
    m.nodes.assign(n, Impl::Node{0.0, -1, 0});
    m.generation = 0;
    m.jps_marks.Resize(n);
  }
  m.components.clear();
  m.passable.clear();
}

float AStarPlanner::PenaltyAt(float distance) const {
  const double range = options_.penalty_range_m;
  if (!(distance >= 0.0f) || !(distance < range)) return 0.0f;
  return static_cast<float>(options_.penalty_weight * std::pow((range - distance) / range, options_.penalty_exponent));
}

void AStarPlanner::UpdateMap(const ObstacleDistanceGrid& d, const mapping::CellRect& changed) {
  Impl& m = *impl_;
  if (m.width != d.width() || m.height != d.height() || m.resolution != d.resolution() || m.origin_x != d.origin_x() ||
      m.origin_y != d.origin_y()) {
    SetMap(d);
    return;
  }
  if (changed.empty()) return;
  const int x0 = std::max(0, changed.x0), x1 = std::min(m.width - 1, changed.x1);
  const int y0 = std::max(0, changed.y0), y1 = std::min(m.height - 1, changed.y1);
  for (int y = y0; y <= y1; ++y) {
    const float* src = &d.distances()[static_cast<size_t>(y) * m.width];
    for (int x = x0; x <= x1; ++x) {
      const int i = m.Index(x, y);
      m.dist[i] = src[x];
      if (m.use_penalty) m.penalty[i] = PenaltyAt(src[x]);
    }
  }
  // Connectivity and the jump point rows span the grid: rebuilt when next asked for.
  m.components.clear();
  m.passable.clear();
}

std::vector<double> AStarPlanner::EasingClearances() const {
  std::vector<double> out;
  const double r = options_.robot_radius_m;
  if (options_.ease_start_m > 0.0) {
    const double first = r + options_.ease_start_m;
    const double last = std::max(r, first - options_.ease_max_m);
    const double step = options_.ease_step_m > 0.0 ? options_.ease_step_m : options_.ease_max_m;
    for (int k = 0;; ++k) {
      const double c = first - k * step;
      if (c < last - 1e-9 || c <= r + 1e-9) break;
      out.push_back(c);
      if (step <= 0.0) break;
    }
  }
  out.push_back(r);
  return out;
}

PlanResult AStarPlanner::PlanSteppingOut(const motion::Pose2D& start, const motion::Pose2D& goal, double max_step_m) {
  if (!has_map()) throw std::logic_error("AStarPlanner::PlanSteppingOut without a map");
  const double radius = options_.robot_radius_m;
  if (DistanceAt(start.x, start.y) > radius) return Plan(start, goal);
  // The nearest cell centre outside the radius that a straight step reaches keeping half of it.
  const double res = impl_->resolution;
  const int reach = static_cast<int>(std::ceil(max_step_m / res));
  double best = std::numeric_limits<double>::infinity();
  std::optional<motion::Pose2D> out;
  int cx, cy;
  if (impl_->ToCell(start.x, start.y, &cx, &cy)) {
    for (int dy = -reach; dy <= reach; ++dy) {
      for (int dx = -reach; dx <= reach; ++dx) {
        const double x = impl_->origin_x + (cx + dx + 0.5) * res, y = impl_->origin_y + (cy + dy + 0.5) * res;
        const double d = std::hypot(x - start.x, y - start.y);
        if (d >= best || d > max_step_m || DistanceAt(x, y) <= radius) continue;
        if (!SegmentIsClear(start.x, start.y, x, y, 0.5 * radius)) continue;
        best = d;
        out = motion::Pose2D{x, y, std::atan2(y - start.y, x - start.x)};
      }
    }
  }
  if (!out) return Plan(start, goal);  // reports kStartInCollision
  PlanResult r = Plan(*out, goal);
  if (r.status == PlanStatus::kFound) r.path.insert(r.path.begin(), start);
  return r;
}

double AStarPlanner::DistanceAt(double x, double y) const {
  int cx, cy;
  if (!impl_->ToCell(x, y, &cx, &cy)) return -1.0;
  return impl_->dist[impl_->Index(cx, cy)];
}

namespace {

std::vector<motion::Pose2D> HeadingsAlong(std::vector<motion::Pose2D> path) {
  for (size_t i = 1; i + 1 < path.size(); ++i) {
    path[i].theta = std::atan2(path[i + 1].y - path[i].y, path[i + 1].x - path[i].x);
  }
  return path;
}

}  // namespace

PlanResult AStarPlanner::PlanAtClearance(const motion::Pose2D& start, const motion::Pose2D& goal, double clearance_m) {
  Impl& m = *impl_;
  PlanResult r;
  int s, g;
  const float c = static_cast<float>(clearance_m);
  if (!m.Endpoints(start, goal, std::min(static_cast<float>(options_.robot_radius_m), c), &s, &g, &r.status)) return r;
  r.clearance_m = clearance_m;
  if (s == g) {
    r.status = PlanStatus::kFound;
    r.path = {start, goal};
    return r;
  }
  if (!(m.dist[g] > c)) return r.status = PlanStatus::kUnreachable, r;
  bool budget_hit = false;
  const int64_t budget = options_.node_budget;
  r.searches = 1;
  r.jump_points = UsesJumpPoints();
  bool found;
  if (r.jump_points) {
    found = detail::JumpPointSearch(m.PassableAt(c), m.stride, s, g, m.jps_marks, m.nodes, m.open, budget,
                                    &r.expansions, &budget_hit);
  } else {
    found = m.Search(s, g, c, budget, &r.expansions, &budget_hit);
  }
  if (!found) {
    r.status = budget_hit ? PlanStatus::kBudgetExhausted : PlanStatus::kUnreachable;
    return r;
  }
  r.status = PlanStatus::kFound;
  r.cost = m.nodes[g].g;
  std::vector<int> chain;
  for (int i = g; i != -1; i = m.nodes[i].parent) chain.push_back(i);
  std::reverse(chain.begin(), chain.end());
  // Every cell of the path: A*'s parents are neighbours; jump points are joined by straight or
  // diagonal runs, filled in here.
  std::vector<int> cells = {chain.front()};
  for (size_t i = 1; i < chain.size(); ++i) {
    const int dx = chain[i] % m.stride - chain[i - 1] % m.stride, dy = chain[i] / m.stride - chain[i - 1] / m.stride;
    const int step = (dy > 0 ? m.stride : dy < 0 ? -m.stride : 0) + (dx > 0 ? 1 : dx < 0 ? -1 : 0);
    for (int k = chain[i - 1] + step; k != chain[i]; k += step) cells.push_back(k);
    cells.push_back(chain[i]);
  }
  std::vector<motion::Pose2D> path;
  path.reserve(cells.size());
  double length_cells = 0.0;
  for (size_t i = 0; i < cells.size(); ++i) {
    int cx, cy;
    m.CellOf(cells[i], &cx, &cy);
    motion::Pose2D p;
    p.x = m.origin_x + (cx + 0.5) * m.resolution;
    p.y = m.origin_y + (cy + 0.5) * m.resolution;
    path.push_back(p);
    if (i > 0)
      length_cells +=
          (std::abs(cells[i] - cells[i - 1]) == 1 || std::abs(cells[i] - cells[i - 1]) == m.stride) ? 1.0 : kSqrt2;
  }
  r.length_m = length_cells * m.resolution;
  path.front() = start;
  path.back() = goal;
  path = HeadingsAlong(std::move(path));
  switch (options_.prune) {
    case PruneMode::kNone: break;
    case PruneMode::kCollinear: path = PruneCollinear(path); break;
    case PruneMode::kLineOfSight: {
      path = PruneCollinear(path);
      std::vector<motion::Pose2D> out = {path.front()};
      size_t anchor = 0;
      while (anchor + 1 < path.size()) {
        size_t next = anchor + 1;
        for (size_t j = path.size() - 1; j > anchor + 1; --j) {
          if (SegmentIsClear(path[anchor].x, path[anchor].y, path[j].x, path[j].y, clearance_m)) {
            next = j;
            break;
          }
        }
        out.push_back(path[next]);
        anchor = next;
      }
      path = HeadingsAlong(std::move(out));  // keeps the goal's own heading on the last pose
      break;
    }
  }
  r.path = std::move(path);
  return r;
}

PlanResult AStarPlanner::Plan(const motion::Pose2D& start, const motion::Pose2D& goal) {
  Impl& m = *impl_;
  PlanResult r;
  int s, g;
  if (!m.Endpoints(start, goal, static_cast<float>(options_.robot_radius_m), &s, &g, &r.status)) return r;
  int64_t expansions = 0;
  int searches = 0;
  for (double c : EasingClearances()) {
    // Rungs whose passable space does not connect start and goal cannot succeed: skip them
    // without a search (the answer is the same as searching and failing, at O(1) cost).
    if (s != g && !m.Connected(s, g, static_cast<float>(c))) continue;
    PlanResult attempt = PlanAtClearance(start, goal, c);
    expansions += attempt.expansions;
    searches += attempt.searches;
    if (attempt.status == PlanStatus::kFound || attempt.status == PlanStatus::kBudgetExhausted) {
      attempt.expansions = expansions;
      attempt.searches = searches;
      return attempt;
    }
  }
  r.status = PlanStatus::kUnreachable;
  r.expansions = expansions;
  r.searches = searches;
  return r;
}

std::vector<double> AStarPlanner::CostsFrom(const motion::Pose2D& start, double clearance_m) {
  Impl& m = *impl_;
  if (!has_map()) throw std::logic_error("AStarPlanner: CostsFrom called before SetMap");
  std::vector<double> out(static_cast<size_t>(m.width) * m.height, kInf);
  int sx, sy;
  if (!m.ToCell(start.x, start.y, &sx, &sy)) return out;
  int64_t expansions = 0;
  bool budget_hit = false;
  m.Search(m.Index(sx, sy), -1, static_cast<float>(clearance_m), 0, &expansions, &budget_hit);
  const uint32_t closed_mark = 2 * m.generation + 1;
  for (int y = 0; y < m.height; ++y) {
    for (int x = 0; x < m.width; ++x) {
      const Impl::Node& n = m.nodes[m.Index(x, y)];
      if (n.mark == closed_mark) out[static_cast<size_t>(y) * m.width + x] = n.g;
    }
  }
  return out;
}

bool AStarPlanner::SegmentIsClear(double ax, double ay, double bx, double by, double clearance_m) const {
  const Impl& m = *impl_;
  const float c = static_cast<float>(clearance_m);
  const double x0 = (ax - m.origin_x) / m.resolution, y0 = (ay - m.origin_y) / m.resolution;
  const double x1 = (bx - m.origin_x) / m.resolution, y1 = (by - m.origin_y) / m.resolution;
  int cx = static_cast<int>(std::floor(x0)), cy = static_cast<int>(std::floor(y0));
  const int ex = static_cast<int>(std::floor(x1)), ey = static_cast<int>(std::floor(y1));
  auto clear = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < m.width && y < m.height && m.dist[m.Index(x, y)] > c;
  };
  const double dx = x1 - x0, dy = y1 - y0;
  const int step_x = dx > 0 ? 1 : -1, step_y = dy > 0 ? 1 : -1;
  const double t_dx = dx != 0 ? std::abs(1.0 / dx) : kInf;
  const double t_dy = dy != 0 ? std::abs(1.0 / dy) : kInf;
  double t_x = dx != 0 ? ((step_x > 0 ? cx + 1 - x0 : x0 - cx) * t_dx) : kInf;
  double t_y = dy != 0 ? ((step_y > 0 ? cy + 1 - y0 : y0 - cy) * t_dy) : kInf;
  const int max_steps = std::abs(ex - cx) + std::abs(ey - cy) + 2;
  for (int i = 0; i <= max_steps; ++i) {
    if (!clear(cx, cy)) return false;
    if (cx == ex && cy == ey) return true;
    if (std::abs(t_x - t_y) < 1e-12) {
      // Through a corner: both cells beside it are touched in the limit; require them too.
      if (!clear(cx + step_x, cy) || !clear(cx, cy + step_y)) return false;
      cx += step_x;
      cy += step_y;
      t_x += t_dx;
      t_y += t_dy;
    } else if (t_x < t_y) {
      cx += step_x;
      t_x += t_dx;
    } else {
      cy += step_y;
      t_y += t_dy;
    }
  }
  return cx == ex && cy == ey && clear(cx, cy);
}

std::vector<motion::Pose2D> PruneCollinear(const std::vector<motion::Pose2D>& path) {
  if (path.size() <= 2) return path;
  std::vector<motion::Pose2D> out = {path.front()};
  for (size_t i = 1; i + 1 < path.size(); ++i) {
    const double ax = path[i].x - out.back().x, ay = path[i].y - out.back().y;
    const double bx = path[i + 1].x - path[i].x, by = path[i + 1].y - path[i].y;
    const double cross = ax * by - ay * bx;
    const double scale = std::hypot(ax, ay) * std::hypot(bx, by);
    if (std::abs(cross) > 1e-9 * std::max(scale, 1e-12)) out.push_back(path[i]);
  }
  out.push_back(path.back());
  return out;
}

}  // namespace mbot::planning
