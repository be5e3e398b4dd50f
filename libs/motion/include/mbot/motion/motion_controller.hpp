// Waypoint motion controllers for the differential-drive MBot: pose in, (v, ω) out, once per
// control step (the simulator and the robot run them at ~50 Hz). Two steering laws share one
// arrival logic:
//  - rotate-translate-rotate (the botlab "smart maneuver"): drive at each waypoint in turn, turning
//    in place whenever it lies too far off the nose, then turn in place to the final heading;
//  - pure pursuit: steer along the arc through a look-ahead point on the waypoint polyline, which
//    follows curves without the stop-and-turn of RTR.
// Every command is clamped to the speed limits and rate-limited against the previous command, so a
// downstream wheel controller never sees a step it cannot follow.
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include "mbot/motion/pose2d.hpp"
#include "mbot/msgs/status.hpp"

namespace mbot::motion {

// Body-frame velocity command (the message vocabulary's): forward speed (m/s), turn rate (rad/s).
using msgs::VelocityCommand;

enum class ControllerKind { kRotateTranslateRotate, kPurePursuit };

struct MotionControllerOptions {
  ControllerKind kind = ControllerKind::kRotateTranslateRotate;
  double max_speed_m_s = 0.3;
  // Faster spins make the wheels slip (odometry then lies about the heading) and smear each lidar
  // sweep over a large angle; 2.5 rad/s still turns a quarter circle in well under a second.
  double max_turn_rate_rad_s = 2.5;
  double max_accel_m_s2 = 0.5;
  double max_angular_accel_rad_s2 = 6.0;
  double final_tolerance_m = 0.02;         // position tolerance at the last waypoint
  double intermediate_tolerance_m = 0.08;  // radius at which an intermediate waypoint counts as passed
  // RTR: the same at a waypoint after the first where the path turns by more than turn_in_place_rad
  // (the robot stops and turns there). Heading on from short of such a corner cuts it by up to this
  // much, towards whatever the path went round (0: intermediate_tolerance_m).
  double corner_tolerance_m = 0.0;
  double final_heading_tolerance_rad = 0.05;
  // Beyond this bearing error to the target the robot turns in place (v = 0) instead of driving an
  // arc; RTR also comes to a stop at waypoints where the path turns by more than this.
  double turn_in_place_rad = M_PI / 4;
  // v = k_distance · (distance left to the next stop), capped by max_speed_m_s and by the speed
  // from which max_accel_m_s2 still stops in that distance (1/s).
  double k_distance = 2.0;
  // ω = k_bearing · bearing error (1/s). Keep it above k_distance: the bearing to a point being
  // approached grows as the distance shrinks, and a weaker turn gain would orbit the point.
  double k_bearing = 4.0;
  double lookahead_m = 0.25;  // pure pursuit: arc length from the projection to the look-ahead point
  // A path of one pose (a correction at the goal) nearer than this and behind the robot is reached
  // by backing up, not by turning round (0: never reverse).
  double reverse_within_m = 0.10;
};

struct ControllerProgress {
  size_t waypoint_index = 0;  // waypoint being driven to; waypoint_count once arrived
  size_t waypoint_count = 0;
  double distance_to_goal_m = 0.0;  // straight line from the last pose given to Update to the final waypoint
  bool arrived = false;
};

class MotionController {
 public:
  explicit MotionController(const MotionControllerOptions& options);

  // Replaces the path (world frame, metres/radians). Waypoint headings are ignored except the last
  // one, which is the heading to finish in. The previous command is kept so the rate limits hold
  // across a path change; an empty path just brings the robot to a stop and reports arrival.
  void SetPath(const std::vector<Pose2D>& waypoints);

  // One control step: `pose` is the robot's world-frame pose now, dt_s the time since the previous
  // call (s). Returns a command with |v| ≤ max_speed_m_s, |ω| ≤ max_turn_rate_rad_s that differs
  // from the previous command by at most max_accel·dt and max_angular_accel·dt (dt_s ≤ 0 repeats
  // the previous command). Never drives backwards. Once arrived it returns zero until SetPath.
  VelocityCommand Update(const Pose2D& pose, double dt_s);

  const ControllerProgress& progress() const { return progress_; }
  bool arrived() const { return progress_.arrived; }

 private:
  enum class Phase { kFollow, kAlign, kSettle };  // kSettle: ramp to zero, then arrived

  VelocityCommand Target(const Pose2D& pose);
  // Pure pursuit step; returns false once the robot is within final tolerance of the end.
  bool PurePursuit(const Pose2D& pose, VelocityCommand* cmd);
  // Distance RTR can cover from `pose` before it must stop (final waypoint or a sharp turn).
  double RtrStopDistance(const Pose2D& pose) const;
  // RTR: how near intermediate waypoint k must be passed (a sharp turn's corner, or any other).
  double PassTolerance(size_t k) const;
  // Turn in place or drive towards `goal` (RTR law) with speed from `stop_distance_m`.
  VelocityCommand DriveTowards(const Pose2D& pose, double gx, double gy, double stop_distance_m) const;
  double Speed(double stop_distance_m) const;
  double TurnRate(double heading_error_rad) const;

  MotionControllerOptions options_;
  std::vector<Pose2D> waypoints_;
  Phase phase_ = Phase::kSettle;
  size_t target_ = 0;  // RTR: current waypoint
  // Pure pursuit: the polyline (robot start prepended on the first Update), cumulative arc length
  // at each vertex, the segment the robot projects onto and the projection's arc length.
  std::vector<Pose2D> path_;
  std::vector<double> arc_;
  size_t segment_ = 0;
  double projection_m_ = 0.0;
  VelocityCommand last_;
  ControllerProgress progress_;
};

// Exact kinematic unicycle: drives the arc of constant (v, ω) for dt_s seconds from `p`.
Pose2D StepUnicycle(const Pose2D& p, const VelocityCommand& c, double dt_s);

}  // namespace mbot::motion
