#include "mbot/planning/benchmark_rules.hpp"

#include <cmath>

namespace mbot::planning {

bool WaypointIsSafe(const mapping::OccupancyGrid& map, double x, double y, double radius) {
  int cx, cy;
  map.WorldToCell(x, y, &cx, &cy);
  const int r = static_cast<int>(std::ceil(radius / map.resolution()));
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      const int nx = cx + dx, ny = cy + dy;
      if (!map.IsInside(nx, ny)) continue;
      if (std::hypot(dx, dy) * map.resolution() <= radius && map.at(nx, ny) > 0) return false;
    }
  }
  return true;
}

CaseOutcome JudgeBotlabCase(const mapping::OccupancyGrid& map, const ObstacleDistanceGrid& distances,
                            const motion::Pose2D& goal, bool expect_path, double radius, const PlanResult& result,
                            int index) {
  // Goal validity as the botlab test checks it: the goal cell's obstacle distance exceeds the radius.
  int gx, gy;
  map.WorldToCell(goal.x, goal.y, &gx, &gy);
  const bool goal_valid = distances.IsInside(gx, gy) && distances.at(gx, gy) > radius;
  CaseOutcome c;
  c.index = index;
  c.expected = expect_path;
  c.status = ToString(result.status);
  c.clearance_m = result.clearance_m;
  c.waypoints = result.path.size();
  c.length_m = result.length_m;
  c.expansions = result.expansions;
  if (goal_valid && result.path.size() > 1) {
    int lx, ly;
    map.WorldToCell(result.path.back().x, result.path.back().y, &lx, &ly);
    c.found = lx == gx && ly == gy;
  }
  c.valid = true;
  for (const auto& p : result.path) c.valid = c.valid && WaypointIsSafe(map, p.x, p.y, radius);
  c.passed = c.expected ? (c.found && c.valid) : !c.found;
  return c;
}

AStarOptions MovingAiPlannerOptions(SearchAlgorithm search) {
  AStarOptions a;
  a.search = search;
  a.robot_radius_m = 0.0;
  a.ease_start_m = 0.0;
  a.ease_max_m = 0.0;
  a.penalty_weight = 0.0;
  a.prune = PruneMode::kNone;
  return a;
}

}  // namespace mbot::planning
