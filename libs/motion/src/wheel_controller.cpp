#include "mbot/motion/wheel_controller.hpp"

#include <algorithm>
#include <cmath>

namespace mbot::motion {

LowPassFilter::LowPassFilter(double time_constant_s, double dt_s)
    : alpha_(time_constant_s > 0 ? dt_s / (time_constant_s + dt_s) : 1.0) {}

double LowPassFilter::Update(double x) {
  y_ += alpha_ * (x - y_);
  return y_;
}

WheelSpeedController::WheelSpeedController(const WheelControllerOptions& options, const RobotGeometry& geometry,
                                           const MotorCalibration& calibration)
    : options_(options),
      geometry_(geometry),
      calibration_(calibration),
      v_(options.v_time_constant_s, options.dt_s),
      w_(options.w_time_constant_s, options.dt_s),
      left_(options),
      right_(options) {}

void WheelSpeedController::Reset() {
  v_.Reset();
  w_.Reset();
  left_ = Wheel(options_);
  right_ = Wheel(options_);
}

double WheelSpeedController::Step(Wheel* wheel, const WheelCalibration& calibration, double target, double measured) {
  const double speed = wheel->measured.Update(measured);
  const double error = target - speed;
  double correction = 0.0;
  if (options_.feedback) {
    const double derivative = wheel->started ? (error - wheel->last_error) / options_.dt_s : 0.0;
    const double integral = wheel->integral + error * options_.dt_s;
    const double limit = options_.ki > 0 ? options_.max_integral_rad_s / options_.ki : 0.0;
    correction = options_.kp * error + options_.ki * std::clamp(integral, -limit, limit) + options_.kd * derivative;
    // Anti-windup: keep the new integral only if the duty it leads to is not pushing further into
    // saturation in the direction of the error.
    const double duty = calibration.DutyFor(target + correction) * calibration.motor_polarity;
    const bool saturated = std::abs(duty) >= 1.0 && (duty > 0) == (error > 0);
    if (!options_.anti_windup || !saturated) wheel->integral = std::clamp(integral, -limit, limit);
    wheel->last_error = error;
    wheel->started = true;
  }
  const double reference = options_.feed_forward ? target + correction : correction;
  return std::clamp(wheel->pwm.Update(calibration.DutyFor(reference)), -1.0, 1.0);
}

WheelDuties WheelSpeedController::Update(double v_m_s, double w_rad_s, double left_measured, double right_measured) {
  const double v = v_.Update(v_m_s), w = w_.Update(w_rad_s);
  WheelDuties out;
  out.left_target_rad_s = (v - w * geometry_.base_radius_m) / geometry_.wheel_radius_m;
  out.right_target_rad_s = (v + w * geometry_.base_radius_m) / geometry_.wheel_radius_m;
  out.left = Step(&left_, calibration_.left, out.left_target_rad_s, left_measured);
  out.right = Step(&right_, calibration_.right, out.right_target_rad_s, right_measured);
  return out;
}

}  // namespace mbot::motion
