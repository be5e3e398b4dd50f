#include "mbot/motion/motion_config.hpp"

#include <string>

#include "mbot/common/config.hpp"

namespace mbot::motion {

MotionControllerOptions ParseMotionControllerOptions(config::Section& s, const MotionControllerOptions& defaults) {
  MotionControllerOptions c = defaults;
  c.kind = s.GetEnum("controller", c.kind,
                     {{"rotate_translate_rotate", ControllerKind::kRotateTranslateRotate},
                      {"pure_pursuit", ControllerKind::kPurePursuit}},
                     "waypoint controller");
  c.max_speed_m_s = s.GetDouble("max_speed_m_s", c.max_speed_m_s, "speed limit [m/s]", 0.01, 2.0);
  c.max_turn_rate_rad_s =
      s.GetDouble("max_turn_rate_rad_s", c.max_turn_rate_rad_s, "turn-rate limit [rad/s]", 0.05, 10.0);
  c.max_accel_m_s2 = s.GetDouble("max_accel_m_s2", c.max_accel_m_s2, "acceleration limit [m/s^2]", 0.01, 10.0);
  c.max_angular_accel_rad_s2 = s.GetDouble("max_angular_accel_rad_s2", c.max_angular_accel_rad_s2,
                                           "angular acceleration limit [rad/s^2]", 0.1, 100.0);
  c.final_tolerance_m =
      s.GetDouble("final_tolerance_m", c.final_tolerance_m, "arrival tolerance at the last waypoint [m]", 0.001, 1.0);
  c.intermediate_tolerance_m = s.GetDouble("intermediate_tolerance_m", c.intermediate_tolerance_m,
                                           "an intermediate waypoint counts as passed this close [m]", 0.001, 2.0);
  c.corner_tolerance_m = s.GetDouble("corner_tolerance_m", c.corner_tolerance_m,
                                     "rotate_translate_rotate: the same at a waypoint where the path turns by more "
                                     "than 45 degrees (a corner it stops at; 0: intermediate_tolerance_m) [m]",
                                     0.0, 2.0);
  c.final_heading_tolerance_rad = s.GetDouble("final_heading_tolerance_rad", c.final_heading_tolerance_rad,
                                              "heading tolerance at the last waypoint [rad]", 0.001, 3.2);
  c.lookahead_m = s.GetDouble("lookahead_m", c.lookahead_m, "pure pursuit look-ahead [m]", 0.01, 5.0);
  c.reverse_within_m =
      s.GetDouble("reverse_within_m", c.reverse_within_m,
                  "a correction to a final pose this near and behind backs up instead of turning round [m]", 0.0, 1.0);
  return c;
}

WheelOdometryOptions ParseWheelConstants(config::Section& s, RobotGeometry* geometry) {
  RobotGeometry g;
  g.wheel_radius_m = 0.5 * s.GetDouble("wheel_diameter_m", 2.0 * g.wheel_radius_m, "wheel diameter [m]", 1e-3, 1.0);
  g.base_radius_m = s.GetDouble("base_radius_m", g.base_radius_m,
                                "half the distance between the wheels' contact points [m]", 1e-3, 2.0);
  g.gear_ratio = s.GetDouble("gear_ratio", g.gear_ratio, "motor turns per wheel turn", 1e-3, 1e4);
  g.encoder_resolution =
      s.GetDouble("encoder_resolution", g.encoder_resolution, "encoder counts per motor turn", 1.0, 1e6);
  g.left_encoder_polarity = s.GetEnum("left_encoder_polarity", 1, {{"1", 1}, {"-1", -1}},
                                      "1 if the left encoder counts up when the wheel turns forward, else -1");
  g.right_encoder_polarity = s.GetEnum("right_encoder_polarity", 1, {{"1", 1}, {"-1", -1}},
                                       "1 if the right encoder counts up when the wheel turns forward, else -1");
  WheelOdometryOptions w = g.Odometry();
  const double l =
      s.GetDouble("left_m_per_tick", 0.0,
                  "override: metres per left-wheel tick, signed with the polarity (0: from the geometry)", -1.0, 1.0);
  const double r =
      s.GetDouble("right_m_per_tick", 0.0,
                  "override: metres per right-wheel tick, signed with the polarity (0: from the geometry)", -1.0, 1.0);
  const double b =
      s.GetDouble("wheel_base_m", 0.0, "override: distance between the wheels [m] (0: 2 x base_radius_m)", 0.0, 4.0);
  if (l != 0.0) w.left_m_per_tick = l;
  if (r != 0.0) w.right_m_per_tick = r;
  if (b != 0.0) w.wheel_base_m = b;
  if (geometry) *geometry = g;
  return w;
}

}  // namespace mbot::motion
