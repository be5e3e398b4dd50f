// Motion keys shared by the stages that integrate encoder ticks (odometry, slam with
// odometry = encoders) and drive the wheels: the robot's wheel constants.
#pragma once

#include "mbot/motion/robot_geometry.hpp"
#include "mbot/motion/wheel_odometry.hpp"

namespace mbot::config {
class Section;
}

namespace mbot::app {

// Reads the robot's geometry (wheel_diameter_m, base_radius_m, gear_ratio, encoder_resolution,
// left/right_encoder_polarity; classic MBot by default) and the optional per-tick overrides
// (left_m_per_tick, right_m_per_tick, wheel_base_m; 0 = derived from the geometry) for robots whose
// constants are only known per tick. Returns the dead-reckoning constants.
motion::WheelOdometryOptions ParseWheelConstants(config::Section& section, motion::RobotGeometry* geometry = nullptr);

}  // namespace mbot::app
