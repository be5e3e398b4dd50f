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
};

struct Frontier {
  std::vector<int> cells;   // row-major cell indices of the map
  double centroid_x = 0.0;  // world frame [m]
  double centroid_y = 0.0;
  int size() const { return static_cast<int>(cells.size()); }
};

// Free cells (log-odds < 0) with an unknown 4-neighbour, grouped 8-connected by BFS; regions
// smaller than options.min_cells are dropped. Sorted by size, largest first.
std::vector<Frontier> FindFrontiers(const mapping::OccupancyGrid& map, const FrontierOptions& options);

struct FrontierGoal {
  int frontier = -1;      // index into the frontier list
  motion::Pose2D target;  // the reachable cell chosen for it
  double cost = 0.0;      // path cost from the robot (planner cost model)
};

// For each frontier, the cell the robot can reach: its centroid when that cell is reachable,
// otherwise the reachable cell nearest the centroid within options.search_radius_m that sees it
// (no occupied cell on the line between; the nearest reachable cell when none does). Costs come
// from one Dijkstra search from `robot` at `clearance_m`. Returns the goals sorted by cost, and in
// `unreachable` the indices of frontiers with no reachable cell.
std::vector<FrontierGoal> RankFrontierGoals(const std::vector<Frontier>& frontiers, const motion::Pose2D& robot,
                                            const mapping::OccupancyGrid& map, AStarPlanner& planner,
                                            double clearance_m, const FrontierOptions& options,
                                            std::vector<int>* unreachable = nullptr);

}  // namespace mbot::planning
