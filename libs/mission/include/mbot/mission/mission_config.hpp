// INI parsing for the mission's options. The algorithm headers never see the INI reader.
#pragma once

#include "mbot/mission/mission.hpp"

namespace mbot::config {
class Section;
}

namespace mbot::mission {

// Keys task, waypoints, targets, dropoffs, deliveries, the motion controller's keys
// (motion::ParseMotionControllerOptions), the exploration keys (planning::ParseExplorationOptions),
// explore_period_s, start_delay_s, max_pose_age_s, control_lag_s, max_corrections, stuck_s,
// max_stalls, backoff_s, dwell_s. Checks that the task's inputs are there (waypoints for the
// circuit, enough targets and a drop-off for the Warehouse). Throws config::ConfigError naming the
// section and key.
MissionOptions ParseMissionOptions(config::Section& section);

}  // namespace mbot::mission
