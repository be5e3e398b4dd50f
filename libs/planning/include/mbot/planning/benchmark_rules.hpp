// The planning benchmarks' rules. The botlab A* test (astar_test): a case expecting a path passes when the planner's
// last waypoint is the goal's cell, the goal is valid (its obstacle distance exceeds the robot
// radius) and no waypoint has an occupied cell within the robot radius on the occupancy grid itself;
// a case expecting none passes when no path reaches the goal.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>

#include "mbot/mapping/occupancy_grid.hpp"
#include "mbot/planning/astar.hpp"
#include "mbot/planning/obstacle_distance_grid.hpp"

namespace mbot::planning {

struct CaseOutcome {
  int index = 0;
  bool expected = false;  // a path was expected
  bool found = false;     // the path reaches the goal's cell (a valid goal)
  bool valid = false;     // every waypoint is clear of obstacles by the robot radius
  bool passed = false;
  std::string status;
  double clearance_m = 0.0;
  size_t waypoints = 0;
  double length_m = 0.0;
  int64_t expansions = 0;
};

// A waypoint is invalid when a cell with log-odds > 0 lies within `radius` of its cell.
bool WaypointIsSafe(const mapping::OccupancyGrid& map, double x, double y, double radius);

// Judges the planner's `result` for one case (goal `goal`, a path expected or not).
CaseOutcome JudgeBotlabCase(const mapping::OccupancyGrid& map, const ObstacleDistanceGrid& distances,
                            const motion::Pose2D& goal, bool expect_path, double robot_radius_m,
                            const PlanResult& result, int index);

// Moving AI scenarios: the planner on bare grid cells (no robot radius, easing, penalty or pruning),
// with `search` (A* or jump points); a scenario is solved optimally when a path was found whose
// length is within `tolerance` of the scenario's optimum.
AStarOptions MovingAiPlannerOptions(SearchAlgorithm search);
// One scenario's outcome: the planner's, and A*'s on the same query when compared.
struct ScenarioResult {
  int index = 0, bucket = 0;
  bool found = false;
  double length = 0.0, optimal = 0.0, time_us = 0.0;
  int64_t expansions = 0;
  double astar_length = 0.0, astar_time_us = 0.0;
  bool astar_found = false;
};
inline bool SolvedOptimally(bool found, double length, double optimal, double tolerance) {
  return found && std::abs(length - optimal) <= tolerance;
}

}  // namespace mbot::planning
