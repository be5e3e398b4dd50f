// INI parsing for the motion options (one function per options struct). The algorithm headers
// never see the INI reader.
#pragma once

#include "mbot/motion/motion_controller.hpp"
#include "mbot/motion/robot_geometry.hpp"
#include "mbot/motion/wheel_odometry.hpp"

namespace mbot::config {
class Section;
}

namespace mbot::motion {

// Keys controller (rotate_translate_rotate | pure_pursuit), max_speed_m_s, max_turn_rate_rad_s,
// max_accel_m_s2, max_angular_accel_rad_s2, final_tolerance_m, intermediate_tolerance_m,
// final_heading_tolerance_rad, lookahead_m, reverse_within_m.
MotionControllerOptions ParseMotionControllerOptions(config::Section& section,
                                                     const MotionControllerOptions& defaults = {});

// Reads the robot's geometry (wheel_diameter_m, base_radius_m, gear_ratio, encoder_resolution,
// left/right_encoder_polarity; classic MBot by default) and the optional per-tick overrides
// (left_m_per_tick, right_m_per_tick, wheel_base_m; 0 = derived from the geometry) for robots whose
// constants are only known per tick. Returns the dead-reckoning constants.
WheelOdometryOptions ParseWheelConstants(config::Section& section, RobotGeometry* geometry = nullptr);

}  // namespace mbot::motion
