#include "motion_config.hpp"

#include <string>

#include "mbot/common/config.hpp"

namespace mbot::app {

motion::WheelOdometryOptions ParseWheelConstants(config::Section& s, motion::RobotGeometry* geometry) {
  motion::RobotGeometry g;
  g.wheel_radius_m = 0.5 * s.GetDouble("wheel_diameter_m", 2.0 * g.wheel_radius_m, "wheel diameter [m]", 1e-3, 1.0);
  g.base_radius_m = s.GetDouble("base_radius_m", g.base_radius_m, "half the distance between the wheels' contact points [m]", 1e-3, 2.0);
  g.gear_ratio = s.GetDouble("gear_ratio", g.gear_ratio, "motor turns per wheel turn", 1e-3, 1e4);
  g.encoder_resolution = s.GetDouble("encoder_resolution", g.encoder_resolution, "encoder counts per motor turn", 1.0, 1e6);
  g.left_encoder_polarity = static_cast<int>(std::stoi(s.GetChoice(
      "left_encoder_polarity", "1", {"1", "-1"}, "1 if the left encoder counts up when the wheel turns forward, else -1")));
  g.right_encoder_polarity = static_cast<int>(std::stoi(s.GetChoice(
      "right_encoder_polarity", "1", {"1", "-1"}, "1 if the right encoder counts up when the wheel turns forward, else -1")));
  motion::WheelOdometryOptions w = g.Odometry();
  const double l = s.GetDouble("left_m_per_tick", 0.0, "override: metres per left-wheel tick, signed with the polarity (0: from the geometry)");
  const double r = s.GetDouble("right_m_per_tick", 0.0, "override: metres per right-wheel tick, signed with the polarity (0: from the geometry)");
  const double b = s.GetDouble("wheel_base_m", 0.0, "override: distance between the wheels [m] (0: 2 x base_radius_m)", 0.0, 4.0);
  if (l != 0.0) w.left_m_per_tick = l;
  if (r != 0.0) w.right_m_per_tick = r;
  if (b != 0.0) w.wheel_base_m = b;
  if (geometry) *geometry = g;
  return w;
}

}  // namespace mbot::app
