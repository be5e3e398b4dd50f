#include "mbot/planning/planning_config.hpp"

#include "mbot/common/config.hpp"

namespace mbot::planning {

SearchAlgorithm ParseSearchAlgorithm(config::Section& s, SearchAlgorithm d) {
  const char* names[] = {"auto", "astar", "jps"};
  const std::string search =
      s.GetChoice("search", names[static_cast<int>(d)], {"auto", "astar", "jps"},
                  "search: jps (jump point search, uniform costs only), astar, or auto (jps when penalty_weight = 0)");
  return search == "astar" ? SearchAlgorithm::kAStar
         : search == "jps" ? SearchAlgorithm::kJumpPoint
                           : SearchAlgorithm::kAuto;
}

AStarOptions ParseAStarOptions(config::Section& s, const AStarOptions& d) {
  AStarOptions o = d;
  o.robot_radius_m = s.GetDouble("robot_radius_m", d.robot_radius_m,
                                 "cells whose obstacle distance is at most this are never entered [m]", 0.0, 10.0);
  o.ease_start_m = s.GetDouble("ease_start_m", d.ease_start_m,
                               "easing: the first search asks this much more clearance than the radius [m]", 0.0, 10.0);
  o.ease_step_m =
      s.GetDouble("ease_step_m", d.ease_step_m, "easing: clearance relaxed by this per failed search [m]", 0.0, 10.0);
  o.ease_max_m =
      s.GetDouble("ease_max_m", d.ease_max_m,
                  "easing: relax at most this far below the first clearance, then search at the radius [m]", 0.0, 10.0);
  o.penalty_range_m = s.GetDouble("penalty_range_m", d.penalty_range_m,
                                  "obstacle distance below which travel costs extra [m]", 0.0, 100.0);
  o.penalty_weight = s.GetDouble("penalty_weight", d.penalty_weight,
                                 "extra cost per cell of travel right at an obstacle (0: no penalty)", 0.0, 1e6);
  o.penalty_exponent = s.GetDouble("penalty_exponent", d.penalty_exponent,
                                   "shape of the penalty: weight * ((range - d) / range)^exponent", 0.1, 10.0);
  o.node_budget = s.GetInt("node_budget", d.node_budget, "expansions allowed per search (0: unlimited)", 0);
  const char* names[] = {"none", "collinear", "line_of_sight"};
  const std::string prune =
      s.GetChoice("prune", names[static_cast<int>(d.prune)], {"none", "collinear", "line_of_sight"},
                  "waypoints kept: every cell, heading changes only, or line-of-sight shortcuts");
  o.prune = prune == "none" ? PruneMode::kNone : prune == "collinear" ? PruneMode::kCollinear : PruneMode::kLineOfSight;
  o.search = ParseSearchAlgorithm(s, d.search);
  if (o.search == SearchAlgorithm::kJumpPoint && o.penalty_weight > 0.0 && o.penalty_range_m > 0.0) {
    s.Fail("search", "jps needs uniform step costs: set penalty_weight = 0 (or search = auto)");
  }
  return o;
}

ObstacleDistanceOptions ParseObstacleDistanceOptions(config::Section& s, const ObstacleDistanceOptions& d) {
  ObstacleDistanceOptions o = d;
  o.unknown_is_obstacle = s.GetBool("unknown_is_obstacle", d.unknown_is_obstacle,
                                    "unknown cells (log-odds 0) count as obstacles for distances and paths");
  o.unknown_margin_m =
      s.GetDouble("unknown_margin_m", d.unknown_margin_m,
                  "with unknown_is_obstacle: unknown cells count as this much farther than they are [m]", 0.0, 10.0);
  o.occupied_threshold = static_cast<int>(
      s.GetInt("occupied_threshold", d.occupied_threshold, "cells with log-odds above this are obstacles", -127, 126));
  o.free_threshold = static_cast<int>(s.GetInt("free_threshold", d.free_threshold,
                                               "with unknown_is_obstacle: cells are free at or below this log-odds, "
                                               "unknown between it and occupied_threshold",
                                               -127, -1));
  return o;
}

FrontierOptions ParseFrontierOptions(config::Section& s, const FrontierOptions& d) {
  FrontierOptions o = d;
  o.min_cells = static_cast<int>(
      s.GetInt("min_frontier_cells", d.min_cells, "frontier regions with fewer cells are ignored", 1, 1000000));
  o.min_space_m = s.GetDouble("frontier_min_space_m", d.min_space_m,
                              "a frontier still there when seen from its target, of no more cells than fit across this "
                              "and each within half of it from a wall (a nook, a crack), is a pocket: exploration ends "
                              "complete without it (0: none is) [m]",
                              0.0, 100.0);
  o.search_radius_m = s.GetDouble("frontier_search_radius_m", d.search_radius_m,
                                  "radius searched around a frontier's centroid for a reachable cell [m]", 0.0, 100.0);
  o.free_threshold = static_cast<int>(s.GetInt(
      "frontier_free_threshold", d.free_threshold,
      "frontiers: a cell is free at or below this log-odds; cells between this and frontier_occupied_threshold "
      "(never seen, or faint from a few grazing rays) count as unknown",
      -127, 0));
  o.occupied_threshold = static_cast<int>(s.GetInt("frontier_occupied_threshold", d.occupied_threshold,
                                                   "frontiers: a cell is occupied at or above this log-odds", 1, 127));
  return o;
}

ExplorationOptions ParseExplorationOptions(config::Section& s, const ExplorationOptions& d) {
  ExplorationOptions o = d;
  o.astar = ParseAStarOptions(s, d.astar);
  o.distance = ParseObstacleDistanceOptions(s, d.distance);
  o.frontier = ParseFrontierOptions(s, d.frontier);
  o.home_tolerance_m = s.GetDouble("home_tolerance_m", d.home_tolerance_m,
                                   "exploration is completed when the robot is this close to home [m]", 0.0, 10.0);
  const std::vector<config::PoseValue> home =
      s.GetPoses("home", {},
                 "exploration's home, x, y, theta_deg in the map frame (default: where the robot is when exploration "
                 "starts; set it when resuming a run from a SLAM checkpoint)");
  if (home.size() > 1) s.Fail("home", "one pose, x, y, theta_deg");
  if (!home.empty()) o.home = motion::Pose2D{home[0].x_m, home[0].y_m, home[0].theta_rad};
  o.target_reached_m = s.GetDouble("target_reached_m", d.target_reached_m,
                                   "a frontier target counts as reached this close [m]", 0.0, 10.0);
  o.resolve_wait_s =
      s.GetDouble("resolve_wait_s", d.resolve_wait_s,
                  "a frontier still there this long after its target was reached is tried from another viewpoint, "
                  "then ignored for good [s]",
                  0.0, 600.0);
  o.second_view_m = s.GetDouble("second_view_m", d.second_view_m,
                                "a frontier unresolved at its target is tried once more from a viewpoint at least "
                                "this far from the first (0: given up at once) [m]",
                                0.0, 10.0);
  o.blacklist_s = s.GetDouble("blacklist_s", d.blacklist_s,
                              "how long an unreachable or unresolvable frontier is ignored [s]", 0.0, 1e6);
  o.blacklist_radius_m =
      s.GetDouble("blacklist_radius_m", d.blacklist_radius_m,
                  "frontiers whose centroid is this close to a blacklisted one (and at most twice its size plus "
                  "min_frontier_cells) are ignored too [m]",
                  0.0, 100.0);
  o.frontier_match_m =
      s.GetDouble("frontier_match_m", d.frontier_match_m,
                  "the target frontier still exists while a frontier centroid is this close [m]", 0.0, 100.0);
  o.home_retries = static_cast<int>(s.GetInt("home_retries", d.home_retries,
                                             "at home with reachable frontiers given up only for a while (no path "
                                             "then), forget them and explore again, at most this many times",
                                             0, 100));
  return o;
}

}  // namespace mbot::planning
