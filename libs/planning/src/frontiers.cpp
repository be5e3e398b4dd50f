#include "mbot/planning/frontiers.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mbot::planning {

std::vector<Frontier> FindFrontiers(const mapping::OccupancyGrid& map, const FrontierOptions& options) {
  const int w = map.width(), h = map.height();
  const auto& cells = map.cells();
  auto is_frontier = [&](int x, int y) {
    if (cells[static_cast<size_t>(y) * w + x] >= 0) return false;
    return (x > 0 && cells[static_cast<size_t>(y) * w + x - 1] == 0) ||
           (x + 1 < w && cells[static_cast<size_t>(y) * w + x + 1] == 0) ||
           (y > 0 && cells[static_cast<size_t>(y - 1) * w + x] == 0) ||
           (y + 1 < h && cells[static_cast<size_t>(y + 1) * w + x] == 0);
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
      const int cx = c % w, cy = c / w;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = cx + dx, ny = cy + dy;
          if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
          const int n = ny * w + nx;
          if (state[n] == 1) {
            state[n] = 2;
            queue.push_back(n);
          }
        }
      }
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

namespace {

// True when the straight line between the centres of cells a and b crosses no occupied cell
// (unknown cells do not block: the frontier's centroid usually lies in unknown space). Sampled at a
// quarter cell, so a one-cell wall is never stepped over.
bool SeesThrough(const mapping::OccupancyGrid& map, int ax, int ay, int bx, int by) {
  const int steps = 4 * std::max(std::abs(bx - ax), std::abs(by - ay));
  for (int k = 1; k < steps; ++k) {
    const double t = double(k) / steps;
    const int x = static_cast<int>(std::lround(ax + t * (bx - ax))),
              y = static_cast<int>(std::lround(ay + t * (by - ay)));
    if (map.at(x, y) > 0) return false;
  }
  return true;
}

}  // namespace

std::vector<FrontierGoal> RankFrontierGoals(const std::vector<Frontier>& frontiers, const motion::Pose2D& robot,
                                            const mapping::OccupancyGrid& map, AStarPlanner& planner,
                                            double clearance_m, const FrontierOptions& options,
                                            std::vector<int>* unreachable) {
  std::vector<FrontierGoal> goals;
  if (unreachable) unreachable->clear();
  if (frontiers.empty()) return goals;
  const std::vector<double> cost = planner.CostsFrom(robot, clearance_m);
  const int w = map.width(), h = map.height();
  const int radius_cells = static_cast<int>(std::ceil(options.search_radius_m / map.resolution()));
  for (int i = 0; i < static_cast<int>(frontiers.size()); ++i) {
    const Frontier& f = frontiers[i];
    int cx, cy;
    map.WorldToCell(f.centroid_x, f.centroid_y, &cx, &cy);
    int best = -1, best_blind = -1;
    double best_d2 = std::numeric_limits<double>::infinity(), best_blind_d2 = best_d2;
    // Rings of growing radius around the centroid; the first ring holding reachable cells that
    // see the centroid (no wall between) wins, the cell nearest the centroid within it (and the
    // next ring, which can hold nearer cells by Euclidean distance) is taken. A cell on the other
    // side of a wall is nearer by distance but shows nothing of the frontier: it is used only when
    // no reachable cell within the search radius sees the centroid.
    for (int r = 0; r <= radius_cells && double(r) * r < best_d2; ++r) {
      for (int dy = -r; dy <= r; ++dy) {
        for (int dx = -r; dx <= r; ++dx) {
          if (std::max(std::abs(dx), std::abs(dy)) != r) continue;
          const int x = cx + dx, y = cy + dy;
          if (x < 0 || y < 0 || x >= w || y >= h) continue;
          const double d2 = double(dx) * dx + double(dy) * dy;
          if (d2 > double(radius_cells) * radius_cells) continue;
          const int n = y * w + x;
          if (!std::isfinite(cost[n]) || d2 >= best_d2) continue;
          if (d2 < best_blind_d2) best_blind_d2 = d2, best_blind = n;
          if (SeesThrough(map, x, y, cx, cy)) best_d2 = d2, best = n;
        }
      }
    }
    if (best < 0) best = best_blind;
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
