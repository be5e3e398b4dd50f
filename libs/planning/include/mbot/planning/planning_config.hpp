// INI parsing for the planning options (one function per options struct). The algorithm headers
// never see the INI reader; only the application calls these.
#pragma once

#include "mbot/planning/astar.hpp"
#include "mbot/planning/exploration.hpp"
#include "mbot/planning/frontiers.hpp"
#include "mbot/planning/obstacle_distance_grid.hpp"

namespace mbot::config {
class Section;
}

namespace mbot::planning {

// Keys robot_radius_m, ease_start_m, ease_step_m, ease_max_m, penalty_range_m, penalty_weight,
// penalty_exponent, node_budget, prune. Throws config::ConfigError naming section and key.
AStarOptions ParseAStarOptions(config::Section& section, const AStarOptions& defaults = {});
// Key search (auto | astar | jps), on its own for stages that fix the other planner options.
SearchAlgorithm ParseSearchAlgorithm(config::Section& section, SearchAlgorithm def = SearchAlgorithm::kAuto);
// Keys unknown_is_obstacle, occupied_threshold.
ObstacleDistanceOptions ParseObstacleDistanceOptions(config::Section& section,
                                                     const ObstacleDistanceOptions& defaults = {});
// Keys min_frontier_cells, frontier_search_radius_m, frontier_free_threshold, frontier_occupied_threshold.
FrontierOptions ParseFrontierOptions(config::Section& section, const FrontierOptions& defaults = {});
// Everything above plus home_tolerance_m, target_reached_m, blacklist_s, blacklist_radius_m,
// frontier_match_m.
ExplorationOptions ParseExplorationOptions(config::Section& section, const ExplorationOptions& defaults = {});

}  // namespace mbot::planning
