// Grid A* on an obstacle distance grid: 8-connected, octile heuristic, no diagonal step past an
// obstacle corner, step cost (1 or √2 cells) plus a clearance penalty near obstacles, and the
// botlab "easing factor": search first with a clearance stricter than the robot radius and relax
// it step by step, so the widest corridor that connects start and goal is the one used.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "mbot/motion/pose2d.hpp"
#include "mbot/planning/obstacle_distance_grid.hpp"

namespace mbot::planning {

enum class PruneMode {
  kNone,         // every cell of the grid path
  kCollinear,    // drop waypoints where the heading does not change
  kLineOfSight,  // collinear, then skip waypoints while the straight segment keeps the clearance
};

enum class SearchAlgorithm {
  kAuto,       // jump point search where every step costs its length (no penalty), A* otherwise
  kAStar,      // A* over every cell
  kJumpPoint,  // jump point search (needs uniform step costs: no clearance penalty)
};

struct AStarOptions {
  double robot_radius_m = 0.10;  // cells whose obstacle distance is <= this are never entered
  // Easing factor: the first search requires clearance robot_radius_m + ease_start_m; each failed
  // search relaxes it by ease_step_m, down to ease_max_m looser than the first (never below the
  // robot radius), then once more at the robot radius itself, the hard limit, so a robot or a goal
  // already closer to a wall than the relaxed clearance is still served. ease_start_m = 0 searches
  // once, at the robot radius.
  double ease_start_m = 0.10;
  double ease_step_m = 0.01;
  double ease_max_m = 0.04;
  // Clearance penalty added per cell of travel: weight · ((range − d) / range)^exponent for an
  // obstacle distance d < range (0 beyond), in cells of path length. weight 0 disables it.
  double penalty_range_m = 0.30;
  double penalty_weight = 1.0;
  double penalty_exponent = 2.0;
  // Expansions allowed per search (0: as many as the grid has cells).
  int64_t node_budget = 0;
  PruneMode prune = PruneMode::kCollinear;
  // Jump point search returns paths of the same (optimal) length as A* while expanding only the
  // cells where an optimal path may turn; it applies when clearance is a hard limit and costs
  // are uniform. CostsFrom is always Dijkstra over every cell.
  SearchAlgorithm search = SearchAlgorithm::kAuto;
};

enum class PlanStatus {
  kFound,
  kStartOffMap,
  kGoalOffMap,
  kStartInCollision,  // the start cell is within the robot radius of an obstacle
  kGoalInCollision,   // the goal cell is within the robot radius of an obstacle
  kUnreachable,       // no path at any clearance the easing allows
  kBudgetExhausted,   // node_budget expansions spent without reaching the goal
};

const char* ToString(PlanStatus status);

struct PlanResult {
  PlanStatus status = PlanStatus::kUnreachable;
  // World poses from the start pose to the goal pose (headings along the path, the goal's heading
  // last); empty unless kFound. Start and goal in one cell give [start, goal].
  std::vector<motion::Pose2D> path;
  double clearance_m = 0.0;  // the clearance requirement the returned path satisfies
  double length_m = 0.0;     // length of the grid path (before pruning) in metres
  double cost = 0.0;         // A* cost: length in cells plus penalties
  int64_t expansions = 0;    // nodes expanded over every search of this query
  int searches = 0;          // A* searches run (easing rungs actually searched)
  bool jump_points = false;  // searched by jump point search (expansions count jump points)
};

// Plans on one distance grid. Setting the grid precomputes what every query shares (per-cell
// penalties and, per easing clearance, connected components so impossible rungs are skipped
// without a search); queries then reuse dense arrays reset in O(1) by a generation counter.
class AStarPlanner {
 public:
  explicit AStarPlanner(const AStarOptions& options = {});
  ~AStarPlanner();
  AStarPlanner(AStarPlanner&&) noexcept;
  AStarPlanner& operator=(AStarPlanner&&) noexcept;

  const AStarOptions& options() const { return options_; }
  // Takes a copy of the distances it needs; the grid may be discarded afterwards.
  void SetMap(const ObstacleDistanceGrid& distances);
  // After ObstacleDistanceGrid::Update: takes in only the cells it reported changed (their
  // distances and penalties); connectivity and jump point rows are rebuilt when next needed. The
  // same planner as SetMap(distances) gives. A grid of another size or frame is taken whole.
  void UpdateMap(const ObstacleDistanceGrid& distances, const mapping::CellRect& changed);
  bool has_map() const;

  // Plans from `start` to `goal` (world frame, metres). Throws std::logic_error without a map.
  PlanResult Plan(const motion::Pose2D& start, const motion::Pose2D& goal);

  // Plan, for a robot that may stand inside the robot radius of an obstacle (pushed there, a wall
  // seen late, a pose corrected by localization): it first steps straight out to the nearest cell
  // outside the radius within max_step_m that a segment keeping half the radius reaches; the path
  // then starts at `start`. Plans as Plan does when the start is clear or no such cell exists.
  PlanResult PlanSteppingOut(const motion::Pose2D& start, const motion::Pose2D& goal, double max_step_m = 0.3);

  // Single search at a fixed clearance, no easing (Moving AI benchmarks, tests).
  PlanResult PlanAtClearance(const motion::Pose2D& start, const motion::Pose2D& goal, double clearance_m);

  // Whether queries use jump point search (options().search, kAuto resolved).
  bool UsesJumpPoints() const;

  // The clearances the easing tries, strictest first.
  std::vector<double> EasingClearances() const;

  // Dijkstra costs (same cost model as Plan) from `start` to every cell reachable at `clearance_m`,
  // row-major, +inf where unreachable. Used to pick exploration goals with one search.
  std::vector<double> CostsFrom(const motion::Pose2D& start, double clearance_m);

  // True when the straight segment a → b touches only cells whose obstacle distance exceeds
  // clearance_m (every cell the segment passes through, not samples along it).
  bool SegmentIsClear(double ax, double ay, double bx, double by, double clearance_m) const;

  // Obstacle distance of the cell containing (x, y); -1 off the map.
  double DistanceAt(double x, double y) const;

 private:
  struct Impl;
  float PenaltyAt(float distance) const;
  AStarOptions options_;
  std::unique_ptr<Impl> impl_;
};

// Removes waypoints where the heading does not change (keeps the first and last).
std::vector<motion::Pose2D> PruneCollinear(const std::vector<motion::Pose2D>& path);

}  // namespace mbot::planning
