// Frontiers: known-free cells that touch unknown space, grouped into regions, and the choice of
// which region to explore next.
#pragma once

#include <vector>

#include "mbot/mapping/occupancy_grid.hpp"
#include "mbot/motion/pose2d.hpp"
#include "mbot/planning/astar.hpp"

namespace mbot::planning {

struct FrontierOptions {
  int min_cells = 5;             // regions with fewer frontier cells are ignored
  double search_radius_m = 1.0;  // radial search around a centroid for a reachable free cell
  // What the map really knows. A cell is free for frontier detection only when its log-odds is at
  // or below free_threshold, occupied when at or above occupied_threshold; a cell between the two
  // (never seen, or seen only by a few grazing rays) counts as unknown, so a corridor glimpsed at a
  // slant from its mouth keeps a frontier at the mouth. Log-odds change by miss_odds (1) per ray
  // that crosses a cell: the default asks for about twenty.
  int free_threshold = -20;
  int occupied_threshold = 1;
  // A pocket (IsPocket): a small region no wider than this anywhere along it (0: none is).
  double min_space_m = 0.0;
};

struct Frontier {
  std::vector<int> cells;   // row-major cell indices of the map
  double centroid_x = 0.0;  // world frame [m]
  double centroid_y = 0.0;
  int size() const { return static_cast<int>(cells.size()); }
};

// Confidently free cells (log-odds <= free_threshold) with a 4-neighbour that is neither confidently
// free nor occupied, grouped 8-connected by BFS; regions smaller than options.min_cells are dropped.
// Sorted by size, largest first.
std::vector<Frontier> FindFrontiers(const mapping::OccupancyGrid& map, const FrontierOptions& options);

// Whether `f` is a pocket: no more cells than fit across options.min_space_m (and one), each within
// half of it from an occupied cell. A nook in a wall seen only at a slant, or a crack, too narrow for
// a body that wide. (It does not look past the frontier: a short strip of free cells along one wall,
// with open unknown beside it, counts too; the mission asks only of frontiers that stayed when seen
// from their target.)
bool IsPocket(const Frontier& f, const mapping::OccupancyGrid& map, const FrontierOptions& options);

// What the frontier detection sees in a map, as cell centres (world frame) for a picture: cells
// seen too faintly to count as free or occupied (between the thresholds, not unknown), and the
// frontier cells of the regions FindFrontiers keeps.
struct FrontierLayers {
  std::vector<motion::Pose2D> faint, frontier;
};
FrontierLayers ComputeFrontierLayers(const mapping::OccupancyGrid& map, const FrontierOptions& options);

struct FrontierGoal {
  int frontier = -1;      // index into the frontier list
  motion::Pose2D target;  // the reachable cell chosen for it
  double cost = 0.0;      // path cost from the robot (planner cost model)
};

// A viewpoint from which a frontier was seen not to resolve: a frontier whose centroid lies within
// `match_m` of (frontier_x, frontier_y) gets no goal within `radius_m` of (view_x, view_y).
struct FailedView {
  double frontier_x = 0, frontier_y = 0, view_x = 0, view_y = 0;
};
struct AvoidViews {
  std::vector<FailedView> views;
  double radius_m = 0.25, match_m = 0.5;
};

// For each frontier, the cell the robot can reach: its centroid when that cell is reachable,
// otherwise the reachable cell nearest the centroid within options.search_radius_m that sees it
// (no occupied cell on the line between; the nearest reachable cell when none does). Costs come
// from one Dijkstra search from `robot` at `clearance_m`. Returns the goals sorted by cost, and in
// `unreachable` the indices of frontiers with no reachable cell; a frontier's goal avoids the failed
// viewpoints `avoid` holds for it.
std::vector<FrontierGoal> RankFrontierGoals(const std::vector<Frontier>& frontiers, const motion::Pose2D& robot,
                                            const mapping::OccupancyGrid& map, AStarPlanner& planner,
                                            double clearance_m, const FrontierOptions& options,
                                            std::vector<int>* unreachable = nullptr, const AvoidViews& avoid = {});

}  // namespace mbot::planning
