// How closely the simulated MBot follows the real one (issue 33, item 1). A real log's own velocity
// commands drive a SimRobot from the log's first motion-capture pose, in a world without walls (the
// path is what is compared, and a wall would stop a simulated robot that drifted into it), and what
// it does is set against what the real robot did:
//  - wheel speeds against the log's encoders, each over the same encoder interval;
//  - yaw rate: the simulated gyro (its noise and bias) against the log's gyro;
//  - the path against TRUE_POSE: the position error at the end per metre the real robot drove, and
//    the heading error per full turn it made, beside the same measures of the log's own odometry;
//  - the lidar: at each real beam, the range the simulated lidar gives (the ray cast with its noise
//    and dropout) from the true pose at the beam's own time in a map of the arena, against the real
//    range (residuals, no-return rates, the spread of beam times within a scan).
// Every message is placed at its own stamp when that shares the log's clock (a legacy log's robot
// streams reached the logger in bursts up to 1.6 s late; the motion capture was stamped on arrival):
// the commands drive the simulated robot when the robot sent them, not when they were logged.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <vector>

#include "mbot/motion/pose2d.hpp"
#include "mbot/motion/wheel_odometry.hpp"
#include "mbot/msgs/events.hpp"
#include "mbot/sim/sim_robot.hpp"
#include "mbot/sim/world.hpp"

namespace mbot::sim {

struct SimFidelityOptions {
  SimRobotOptions robot;                    // the robot model under test (geometry: the logged robot's)
  motion::WheelOdometryOptions log_wheels;  // metres per tick of the log's encoders, signed by polarity
  double gyro_scale = 1.0;                  // the log's gyro unit in rad/s (legacy MBot logs: deg/s)
  double max_pose_gap_s = 0.2;              // truth further apart than this is not interpolated
  // The real lidar's valid returns and its pose on the robot.
  double lidar_min_range_m = 0.15;
  double lidar_max_range_m = 12.0;
  motion::Pose2D lidar_mount;
  double residual_histogram_bin_m = 0.01;  // the residual histogram's bins, over ±histogram_range_m
  double residual_histogram_range_m = 0.3;
  // The part of the log compared, in seconds from its first motion-capture pose. The simulated robot
  // always starts at the first truth pose, at rest, driven by every command; at begin_s (> 0) it is
  // re-placed at the truth pose there, moving as it was, and compared from then on. Events after
  // end_s are not taken (a fit on one part of a log, held out on the rest).
  double begin_s = 0.0;
  double end_s = 1e300;
};

// One comparison window (at least 0.2 s; `t_s` is its end since the log's first truth pose). Wheel
// speeds are forward-positive ground speeds of the wheels' rotation [m/s]; the simulated one is the
// unquantised rotation (its encoders' ticks differ by under a tick).
struct WheelWindow {
  double t_s = 0, real_left = 0, real_right = 0, sim_left = 0, sim_right = 0;
};
struct YawWindow {
  double t_s = 0, real = 0, sim = 0;  // mean gyro yaw rate over the window [rad/s]
};

struct SimFidelityResult {
  int commands = 0, commands_refused = 0, encoder_samples = 0, gyro_samples = 0, scans = 0;
  double duration_s = 0, true_path_m = 0, true_turn_deg = 0;
  // Path: the error at the end, per metre of the true path (position) and per 360° of true turning
  // (heading); NaN when the robot did not drive (or turn) enough to divide by (under 0.5 m, 90°).
  double path_drift_m_per_m = 0, odometry_drift_m_per_m = 0;
  double heading_drift_deg_per_turn = 0, odometry_heading_drift_deg_per_turn = 0;
  double path_final_error_m = 0, odometry_final_error_m = 0;
  double path_rmse_m = 0, odometry_rmse_m = 0;                // position error over the whole run
  double wheel_speed_rmse_m_s = 0, wheel_speed_bias_m_s = 0;  // simulated − real
  double yaw_rate_rmse_rad_s = 0, yaw_rate_bias_rad_s = 0;
  // Lidar: residual = real − simulated range, on beams where both returned.
  long long beams = 0, beams_compared = 0;
  double scan_range_residual_median_m = 0;  // of |residual|
  double scan_range_residual_p95_m = 0;     // of |residual|
  double scan_range_residual_signed_median_m = 0;
  double no_return_rate_real = 0, no_return_rate_sim = 0;
  double beam_time_spread_real_s = 0;  // median over scans of (last − first beam time)
  std::vector<WheelWindow> wheel_windows;
  std::vector<YawWindow> yaw_windows;
  std::vector<long long> residual_histogram;  // signed residuals, bins of residual_histogram_bin_m from −range
  // For plotting: the paths in the truth frame (odometry anchored at the first truth pose).
  // fidelity_series: at each simulated sample, its time since the first truth pose, and the log's
  // odometry there when it has one (NaN poses otherwise).
  std::vector<double> path_t_s;
  std::vector<motion::Pose2D> truth_path, sim_path, odometry_path;
};

class SimFidelity {
 public:
  // `arena`: a map of the logged arena in the truth frame (nullopt: no scan comparison).
  SimFidelity(const SimFidelityOptions& options, std::optional<World> arena, uint64_t seed);
  ~SimFidelity();
  SimFidelity(const SimFidelity&) = delete;
  SimFidelity& operator=(const SimFidelity&) = delete;

  // The log's events in order (their t_us: the log's event times).
  void Add(const msgs::Event& event);
  // Throws std::runtime_error naming what the log lacked (motion capture, commands).
  SimFidelityResult Finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mbot::sim
