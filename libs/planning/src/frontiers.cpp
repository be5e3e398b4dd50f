#include "mbot/planning/frontiers.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mbot::planning {

namespace {

// Calls visit(n) for each of cell c's 8 neighbours inside a w × h grid (row-major indices).
template <typename Visit>
void ForEachNeighbour8(int c, int w, int h, Visit visit) {
  const int cx = c % w, cy = c / w;
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      const int nx = cx + dx, ny = cy + dy;
      if ((dx != 0 || dy != 0) && nx >= 0 && ny >= 0 && nx < w && ny < h) visit(ny * w + nx);
    }
  }
}

}  // namespace

std::vector<Frontier> FindFrontiers(const mapping::OccupancyGrid& map, const FrontierOptions& options) {
  const int w = map.width(), h = map.height();
  const auto& cells = map.cells();
  const int free_at = options.free_threshold, occupied_at = options.occupied_threshold;
  auto unknown = [&](size_t i) { return cells[i] > free_at && cells[i] < occupied_at; };
  auto is_frontier = [&](int x, int y) {
    const size_t i = static_cast<size_t>(y) * w + x;
    if (cells[i] > free_at) return false;
    return (x > 0 && unknown(i - 1)) || (x + 1 < w && unknown(i + 1)) || (y > 0 && unknown(i - w)) ||
           (y + 1 < h && unknown(i + w));
  };
  std::vector<uint8_t> state(cells.size(), 0);  // 1: frontier, 2: already grouped
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (is_frontier(x, y)) state[static_cast<size_t>(y) * w + x] = 1;
    }
  }
  std::vector<Frontier> out;
  std::vector<int> queue;
  for (int i = 0; i < static_cast<int>(state.size()); ++i) {
    if (state[i] != 1) continue;
    Frontier f;
    queue.assign(1, i);
    state[i] = 2;
    for (size_t q = 0; q < queue.size(); ++q) {
      const int c = queue[q];
      f.cells.push_back(c);
      ForEachNeighbour8(c, w, h, [&](int n) {
        if (state[n] == 1) {
          state[n] = 2;
          queue.push_back(n);
        }
      });
    }
    if (f.size() < options.min_cells) continue;
    double sx = 0.0, sy = 0.0;
    for (int c : f.cells) {
      double x, y;
      map.CellToWorld(c % w, c / w, &x, &y);
      sx += x;
      sy += y;
    }
    f.centroid_x = sx / f.size();
    f.centroid_y = sy / f.size();
    out.push_back(std::move(f));
  }
  std::stable_sort(out.begin(), out.end(), [](const Frontier& a, const Frontier& b) { return a.size() > b.size(); });
  return out;
}

bool IsPocket(const Frontier& f, const mapping::OccupancyGrid& map, const FrontierOptions& options) {
  if (!(options.min_space_m > 0)) return false;
  // No more cells than fit across the width (and one more, on a slant) ...
  if (f.size() > static_cast<int>(std::ceil(options.min_space_m / map.resolution())) + 1) return false;
  const int w = map.width(), h = map.height();
  const auto& cells = map.cells();
  // ... and every one of them within half the width of an occupied cell: nowhere along it is the
  // opening as wide as the body.
  const double r = 0.5 * options.min_space_m / map.resolution();
  const int k = static_cast<int>(std::ceil(r));
  auto near_wall = [&](int c) {
    const int cx = c % w, cy = c / w;
    for (int dy = -k; dy <= k; ++dy) {
      for (int dx = -k; dx <= k; ++dx) {
        const int x = cx + dx, y = cy + dy;
        if (dx * dx + dy * dy <= r * r && x >= 0 && y >= 0 && x < w && y < h &&
            cells[static_cast<size_t>(y) * w + x] >= options.occupied_threshold)
          return true;
      }
    }
    return false;
  };
  return std::all_of(f.cells.begin(), f.cells.end(), near_wall);
}

FrontierLayers ComputeFrontierLayers(const mapping::OccupancyGrid& map, const FrontierOptions& options) {
  FrontierLayers layers;
  const int w = map.width();
  auto centre = [&](int i) {
    motion::Pose2D p;
    map.CellToWorld(i % w, i / w, &p.x, &p.y);
    return p;
  };
  const auto& cells = map.cells();
  for (int i = 0; i < static_cast<int>(cells.size()); ++i) {
    if (cells[i] != 0 && cells[i] > options.free_threshold && cells[i] < options.occupied_threshold)
      layers.faint.push_back(centre(i));
  }
  for (const Frontier& f : FindFrontiers(map, options)) {
    for (int c : f.cells) layers.frontier.push_back(centre(c));
  }
  return layers;
}

std::vector<FrontierGoal> RankFrontierGoals(const std::vector<Frontier>& frontiers, const motion::Pose2D& robot,
                                            const mapping::OccupancyGrid& map, AStarPlanner& planner,
                                            double clearance_m, const FrontierOptions& options,
                                            std::vector<int>* unreachable, const AvoidViews& avoid) {
  std::vector<FrontierGoal> goals;
  if (unreachable) unreachable->clear();
  if (frontiers.empty()) return goals;
  const std::vector<double> cost = planner.CostsFrom(robot, clearance_m);
  const int w = map.width(), h = map.height();
  const auto& cells = map.cells();
  const int radius_cells = static_cast<int>(std::floor(options.search_radius_m / map.resolution() + 1e-9));
  // Breadth-first from the frontier's cells through mapped free space (log-odds < 0, faint cells
  // too), ring by ring: the first ring holding cells the robot can reach wins, and of those the one
  // it reaches at least cost. Walls and unknown space stop the search, so the goal is never a cell
  // behind a wall that is near the frontier as the crow flies but shows nothing of it; and a
  // frontier is judged by its nearest cell, not its centroid (which a long frontier, or one along a
  // faint band, may put inside a wall).
  // ring_of holds the index of the frontier whose search reached a cell, so no reset is needed
  // between frontiers.
  std::vector<int> ring_of(cells.size(), -1), ring, next;
  for (int i = 0; i < static_cast<int>(frontiers.size()); ++i) {
    const Frontier& f = frontiers[i];
    std::vector<const FailedView*> avoided_views;  // this frontier's
    for (const FailedView& v : avoid.views)
      if (std::hypot(v.frontier_x - f.centroid_x, v.frontier_y - f.centroid_y) <= avoid.match_m)
        avoided_views.push_back(&v);
    ring.assign(f.cells.begin(), f.cells.end());
    for (int c : ring) ring_of[c] = i;
    int best = -1;
    for (int r = 0; r <= radius_cells && !ring.empty() && best < 0; ++r) {
      for (int c : ring) {
        if (!std::isfinite(cost[c]) || (best >= 0 && cost[c] >= cost[best])) continue;
        double x, y;
        map.CellToWorld(c % w, c / w, &x, &y);
        const bool avoided = std::any_of(avoided_views.begin(), avoided_views.end(), [&](const FailedView* v) {
          return std::hypot(v->view_x - x, v->view_y - y) < avoid.radius_m;
        });
        if (!avoided) best = c;
      }
      next.clear();
      for (int c : ring) {
        ForEachNeighbour8(c, w, h, [&](int n) {
          if (ring_of[n] == i || cells[n] >= 0) return;
          ring_of[n] = i;
          next.push_back(n);
        });
      }
      ring.swap(next);
    }
    if (best < 0) {
      if (unreachable) unreachable->push_back(i);
      continue;
    }
    FrontierGoal g;
    g.frontier = i;
    map.CellToWorld(best % w, best / w, &g.target.x, &g.target.y);
    g.target.theta = std::atan2(g.target.y - robot.y, g.target.x - robot.x);
    g.cost = cost[best];
    goals.push_back(g);
  }
  std::stable_sort(goals.begin(), goals.end(),
                   [](const FrontierGoal& a, const FrontierGoal& b) { return a.cost < b.cost; });
  return goals;
}

}  // namespace mbot::planning
