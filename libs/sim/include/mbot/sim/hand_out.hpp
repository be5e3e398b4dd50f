// The organisers' side of an event in another world: what they hand a team — the circuit, the
// Warehouse's targets and drop-offs, the known map — as settings of the event's own configuration
// (`section.key=value`), since the autonomy never reads the simulator's world.
#pragma once

#include <string>
#include <vector>

#include "mbot/sim/world.hpp"

namespace mbot::sim {

// What the event's configuration runs: the mission's task, and whether SLAM localizes in a known
// map (at what resolution).
struct EventSetup {
  std::string task;  // "waypoints", "warehouse", …; another task needs nothing handed out
  bool localization = false;
  double resolution_m = 0.05;
  // The event gives its own circuit (the competition's `waypoints` key): a world without `waypoint`
  // poses (a map) needs none handed out.
  bool waypoints_given = false;
};

// The settings for `setup` in `world`: mission.waypoints (the `waypoint` poses in the `start`
// frame) for task = waypoints, mission.targets and mission.dropoffs for task = warehouse,
// mission.stack (the `stack` lines, <crate>:<crate>, …) for task = heavy_lift, and for
// localization slam.map_file = `map_path`, where the known map (RenderKnownMap) is written.
// Throws std::invalid_argument naming `world_path` when the world lacks what the task needs.
std::vector<std::string> HandOut(const World& world, const std::string& world_path, const EventSetup& setup,
                                 const std::string& map_path);

}  // namespace mbot::sim
