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
// max_stalls, backoff_s, dwell_s, and Heavy Lift's (ParseHeavyLiftOptions). Checks that the task's
// inputs are there (waypoints for the circuit, enough targets and a drop-off for the Warehouse, a
// stack for Heavy Lift). Throws config::ConfigError naming the section and key.
MissionOptions ParseMissionOptions(config::Section& section);

// Heavy Lift's keys: stack (<crate>:<crate it goes on>, …; required when `required`), crate_side_m,
// crate_height_m, fork_tip_x_m, insert_depth_m, standoff_m, carry_height_m, stack_height_m,
// place_standoff_m, retreat_m, approach_speed_m_s, align_lateral_m, align_heading_deg, look_s,
// search_turn_rad_s, max_tag_range_m, max_attempts, no_path_wait_s.
HeavyLiftOptions ParseHeavyLiftOptions(config::Section& section, bool required);

}  // namespace mbot::mission
