// The firmware's wheel-speed controller, as the seed report built it: body velocity commands (v, ω)
// are low-pass filtered, split into wheel speeds, and each wheel gets the motor model's
// feed-forward duty for its target plus a PID correction on the (filtered) measured speed; the duty
// is low-pass filtered again. The PID works in wheel-speed units (its output is added to the target
// before the motor model turns it into a duty), and its integral stops growing while the duty is
// saturated in the error's direction (anti-windup).
#pragma once

#include "mbot/motion/motor_model.hpp"
#include "mbot/motion/robot_geometry.hpp"

namespace mbot::motion {

// First-order low-pass filter y += α (x − y), α = dt / (τ + dt); τ = 0 passes the input through.
class LowPassFilter {
 public:
  LowPassFilter(double time_constant_s, double dt_s);
  double Update(double x);
  void Reset(double value = 0.0) { y_ = value; }
  double value() const { return y_; }

 private:
  double alpha_;
  double y_ = 0.0;
};

struct WheelControllerOptions {
  double dt_s = 0.02;
  // The seed report's gains (Table I) and filter time constants (Table II).
  double kp = 2.2;
  double ki = 2e-5;
  double kd = 1e-5;
  double v_time_constant_s = 0.15;
  double w_time_constant_s = 0.07;
  double wheel_speed_time_constant_s = 0.05;
  double pwm_time_constant_s = 0.1;
  double max_integral_rad_s = 1.0;  // |ki · integral| never exceeds this (the report reset at 1.0)
  bool anti_windup = true;          // no integration while the duty is saturated in the error's direction
  bool feed_forward = true;
  bool feedback = true;
};

struct WheelDuties {
  double left = 0.0, right = 0.0;                            // duty as sent, in [-1, 1]
  double left_target_rad_s = 0.0, right_target_rad_s = 0.0;  // the filtered wheel-speed targets
};

class WheelSpeedController {
 public:
  WheelSpeedController(const WheelControllerOptions& options, const RobotGeometry& geometry,
                       const MotorCalibration& calibration);
  // One control period: commanded body velocity (v forward [m/s], ω counter-clockwise [rad/s]) and
  // the measured forward wheel speeds [rad/s] (polarity already applied). Returns the duties.
  WheelDuties Update(double v_m_s, double w_rad_s, double left_measured_rad_s, double right_measured_rad_s);
  void Reset();

 private:
  struct Wheel {
    Wheel(const WheelControllerOptions& o)
        : measured(o.wheel_speed_time_constant_s, o.dt_s), pwm(o.pwm_time_constant_s, o.dt_s) {}
    LowPassFilter measured, pwm;
    double integral = 0.0, last_error = 0.0;
    bool started = false;
  };
  double Step(Wheel* wheel, const WheelCalibration& calibration, double target, double measured);

  WheelControllerOptions options_;
  RobotGeometry geometry_;
  MotorCalibration calibration_;
  LowPassFilter v_, w_;
  Wheel left_, right_;
};

}  // namespace mbot::motion
