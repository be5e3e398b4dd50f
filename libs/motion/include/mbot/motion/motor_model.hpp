// The MBot motor model and its calibration. Each wheel's steady-state duty follows a line in the
// wheel speed, one per direction: duty = slope·ω + punch, where the punch (the duty that just
// overcomes static friction) is positive forward and negative backward. Polarities say how the
// motor and the encoder are wired: the model itself works in the wheel's forward frame.
// The calibration fits the lines with Ceres from (duty, measured speed) samples, with a robust loss
// because a calibration run has stalls, slips and transients.
#pragma once

#include <string>
#include <cstdint>
#include <vector>

namespace mbot::motion {

struct MotorLine {
  double slope = 0.0;  // duty per rad/s of wheel speed
  double punch = 0.0;  // duty at which the wheel starts turning (signed with the direction)
};

struct WheelCalibration {
  int motor_polarity = 1;           // +1: a positive duty turns the wheel forward
  int encoder_polarity = 1;         // +1: the encoder counts up when the wheel turns forward
  MotorLine forward{0.068, 0.068};  // the seed report's Table III means (both wheels, 6 calibrations)
  MotorLine backward{0.0665, -0.070};

  // Duty to send for a wheel speed [rad/s, forward positive], polarity applied, clamped to [-1, 1];
  // 0 for 0.
  double DutyFor(double wheel_speed_rad_s) const;
  // The steady-state forward wheel speed a duty (as sent, polarity applied) gives: 0 inside the
  // punch dead band.
  double SpeedFor(double duty) const;
};

struct MotorCalibration {
  WheelCalibration left, right;
};

// One calibration sample: the duty as sent to the driver and the wheel speed as the encoder
// measured it (raw signs: the polarities are applied by the fit).
struct MotorSample {
  double duty = 0.0;
  double speed_rad_s = 0.0;
};

// Calibration samples from a log of a calibration run: each wheel's PWM duty paired with the wheel
// speed measured while that duty had held (within `duty_tolerance`) for at least `settle_s` — from
// the measured wheel speeds, and, separately, from speeds derived from encoder ticks.
class SettledMotorSamples {
 public:
  SettledMotorSamples(double settle_s, double duty_tolerance, double rad_per_tick)
      : settle_s_(settle_s), duty_tolerance_(duty_tolerance), rad_per_tick_(rad_per_tick) {}
  void OnDuty(int64_t t_us, double left, double right);
  void OnWheelSpeeds(int64_t t_us, double left_rad_s, double right_rad_s);
  // Cumulative ticks; `delta_time_us` when the message says how long since the previous (else 0).
  void OnEncoderTicks(int64_t t_us, int64_t left_ticks, int64_t right_ticks, int64_t delta_time_us);
  // Per wheel (0 left, 1 right), raw signs.
  const std::vector<MotorSample>* measured() const { return measured_; }
  const std::vector<MotorSample>* from_encoders() const { return from_encoders_; }

 private:
  void Add(int64_t t_us, double left_speed, double right_speed, std::vector<MotorSample>* out);

  double settle_s_, duty_tolerance_, rad_per_tick_;
  std::vector<MotorSample> measured_[2], from_encoders_[2];
  double duty_[2] = {0, 0};
  bool duty_known_[2] = {false, false};
  int64_t duty_since_[2] = {0, 0};
  bool have_ticks_ = false;
  int64_t ticks_t_ = 0, left_ticks_ = 0, right_ticks_ = 0;
};

struct MotorFitOptions {
  int left_motor_polarity = 1, left_encoder_polarity = 1;
  int right_motor_polarity = 1, right_encoder_polarity = 1;
  double min_speed_rad_s = 0.5;  // slower samples are stalls (the wheel is still breaking away): not fitted
  double min_duty = 0.02;        // samples with a smaller duty say nothing about the line
  double loss_scale = 0.02;      // Cauchy loss scale, in duty units: residuals well beyond it (slips) barely count
  double max_abs_slope = 0.10;   // the reports' acceptance criterion
  double max_abs_punch = 0.10;
  int min_samples = 5;  // per wheel and direction
};

struct LineFit {
  MotorLine line;
  double residual_rms = 0.0;  // duty units, over the fitted samples
  int samples = 0;
  bool fitted = false;
};

struct WheelFit {
  LineFit forward, backward;
  int moving_samples = 0;       // samples where the wheel turned (|speed| >= min_speed_rad_s)
  int disagreeing_samples = 0;  // of those, where duty and speed had opposite signs after polarity
  bool encoder_counting = false;
  bool polarity_ok = false;
};

struct MotorFitReport {
  WheelFit left, right;
  MotorCalibration calibration;       // the fitted lines with the configured polarities
  bool acceptable = false;            // polarity right, both encoders counting, every line fitted within the limits
  std::vector<std::string> problems;  // why not acceptable, one line each, naming the wheel
};

MotorFitReport FitMotorCalibration(const std::vector<MotorSample>& left, const std::vector<MotorSample>& right,
                                   const MotorFitOptions& options);

}  // namespace mbot::motion
