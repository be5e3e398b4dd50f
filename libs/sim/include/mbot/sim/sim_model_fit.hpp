// The simulated MBot's model fitted to a real log (issue 33, item 2), not chosen:
//  - motors and firmware: Ceres (Levenberg–Marquardt, Huber loss) fits the wheels' gains, the motor
//    time constant and the firmware's command filters so that the simulated robot, driven by the
//    log's own commands (SimFidelity), turns its wheels as the real encoders counted and its body as
//    the real gyro measured, window by window, on one part of the log; the rest is held out;
//  - sensors: the gyro's noise and bias from the samples taken while the robot stood still, and the
//    lidar's range noise (the spread of each direction's range over the scans of a standstill) and its
//    no-return rate.
// Derivatives are central differences of whole simulations (the simulator has no analytic ones); a
// cache shares each simulation among the windows' residual blocks.
#pragma once

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "mbot/msgs/events.hpp"
#include "mbot/sim/sim_fidelity.hpp"

namespace mbot::sim {

struct SimModelFitOptions {
  // The fit takes [0, split_s) of the log (from its first motion-capture pose), the rest is held out:
  // the same simulation, re-placed at the real pose at split_s and compared from there. NaN: when the
  // wheels have turned half their whole rotation (half the motion is fitted, half held out).
  double split_s = NAN;
  double min_standstill_s = 0.5;  // a standstill: the encoders count nothing for this long
  double huber_m_s = 0.05;        // the robust loss's scale on wheel-speed residuals [m/s]
  int max_iterations = 40;
  double numeric_step = 0.01;  // central differences in log(parameter)
};

struct FittedParameter {
  std::string key;  // the simulator's configuration key
  double before = 0, after = 0, sigma = NAN;
};

struct SensorNoiseEstimate {
  int gyro_samples = 0;  // taken at standstill
  double gyro_bias_rad_s = NAN, gyro_noise_rad_s = NAN;
  int scans = 0;        // at standstill
  long long beams = 0;  // every beam of the log
  double no_return_rate = NAN;
  double range_noise_m = NAN;  // median over directions of the robust spread of their ranges
  // The same over the directions whose median range is under 1.5 m, 1.5-3, 3-4.5 and over 4.5 m.
  std::array<double, 4> range_noise_by_range_m = {NAN, NAN, NAN, NAN};
};

struct SimModelFitResult {
  double split_s = 0, duration_s = 0;
  int windows_fit = 0, iterations = 0;
  double initial_cost = 0, final_cost = 0;
  std::string termination;
  std::vector<FittedParameter> parameters;
  SimRobotOptions fitted;  // the base model with the fitted values
  // The comparison (noise off, as fitted) before and after, on the fitted and on the held-out part.
  SimFidelityResult fit_before, fit_after, held_before, held_after;  // the sensors: EstimateSensorNoise
};

// Whether the log's encoders counted at all (a log where the robot stood fits no motor).
bool WheelsTurned(const std::vector<msgs::Event>& log);

// When the wheels have turned half their rotation over the log, in seconds from its first
// motion-capture pose.
double MotionMidpoint(const std::vector<msgs::Event>& log);

// The start of each standstill (the encoders count nothing for at least min_s) in seconds from the
// log's first motion-capture pose, paired with its length.
std::vector<std::pair<double, double>> FindStandstills(const std::vector<msgs::Event>& log, double min_s);

// The sensors' noise from the log's standstills and all its scans.
SensorNoiseEstimate EstimateSensorNoise(const std::vector<msgs::Event>& log, const SimFidelityOptions& options,
                                        double min_standstill_s);

// Throws std::runtime_error naming what the log lacks (motion capture, commands, encoders, motion in
// either part).
SimModelFitResult FitSimModel(const std::vector<msgs::Event>& log, const SimFidelityOptions& base,
                              const SimModelFitOptions& options);

}  // namespace mbot::sim
