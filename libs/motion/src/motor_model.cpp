#include "mbot/motion/motor_model.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace mbot::motion {

double WheelCalibration::DutyFor(double w) const {
  if (w == 0.0) return 0.0;
  const MotorLine& l = w > 0 ? forward : backward;
  return std::clamp(motor_polarity * (l.slope * w + l.punch), -1.0, 1.0);
}

double WheelCalibration::SpeedFor(double duty) const {
  const double d = motor_polarity * duty;  // in the wheel's forward frame
  if (d > 0 && d > forward.punch && forward.slope > 0) return (d - forward.punch) / forward.slope;
  if (d < 0 && d < backward.punch && backward.slope > 0) return (d - backward.punch) / backward.slope;
  return 0.0;
}

namespace {

struct LineResidual {
  double speed, duty;
  template <typename T>
  bool operator()(const T* slope, const T* punch, T* r) const {
    r[0] = slope[0] * speed + punch[0] - duty;
    return true;
  }
};

LineFit FitLine(const std::vector<std::pair<double, double>>& samples, const MotorLine& start, double loss_scale,
                int min_samples) {
  LineFit fit;
  fit.samples = static_cast<int>(samples.size());
  fit.line = start;
  if (fit.samples < std::max(2, min_samples)) return fit;
  ceres::Problem problem;
  for (const auto& [speed, duty] : samples) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<LineResidual, 1, 1, 1>(new LineResidual{speed, duty}),
                             new ceres::CauchyLoss(loss_scale), &fit.line.slope, &fit.line.punch);
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 100;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  double sum_sq = 0;
  for (const auto& [speed, duty] : samples) {
    const double r = fit.line.slope * speed + fit.line.punch - duty;
    sum_sq += r * r;
  }
  fit.residual_rms = std::sqrt(sum_sq / samples.size());
  fit.fitted = summary.IsSolutionUsable();
  return fit;
}

WheelFit FitWheel(const std::vector<MotorSample>& samples, int motor_polarity, int encoder_polarity,
                  const MotorFitOptions& o, WheelCalibration* out) {
  WheelFit w;
  std::vector<std::pair<double, double>> fwd, bwd;  // (speed, duty) in the wheel's forward frame
  for (const MotorSample& s : samples) {
    if (!std::isfinite(s.duty) || !std::isfinite(s.speed_rad_s)) continue;
    const double duty = motor_polarity * s.duty, speed = encoder_polarity * s.speed_rad_s;
    if (std::abs(speed) < o.min_speed_rad_s || std::abs(duty) < o.min_duty) continue;
    ++w.moving_samples;
    if ((duty > 0) != (speed > 0)) {
      ++w.disagreeing_samples;
      continue;
    }
    (duty > 0 ? fwd : bwd).emplace_back(speed, duty);
  }
  w.encoder_counting = w.moving_samples >= o.min_samples;
  w.polarity_ok = w.encoder_counting && w.disagreeing_samples * 2 < w.moving_samples;
  out->motor_polarity = motor_polarity;
  out->encoder_polarity = encoder_polarity;
  w.forward = FitLine(fwd, out->forward, o.loss_scale, o.min_samples);
  w.backward = FitLine(bwd, out->backward, o.loss_scale, o.min_samples);
  out->forward = w.forward.line;
  out->backward = w.backward.line;
  return w;
}

void Check(const char* name, const WheelFit& w, const MotorFitOptions& o, std::vector<std::string>* problems) {
  auto say = [&](const std::string& what) { problems->push_back(std::string(name) + " wheel: " + what); };
  if (!w.encoder_counting) {
    say("the encoder does not count (" + std::to_string(w.moving_samples) + " samples with the wheel turning)");
    return;
  }
  if (!w.polarity_ok) {
    say("polarity reversed: " + std::to_string(w.disagreeing_samples) + " of " + std::to_string(w.moving_samples) +
        " moving samples turn against the duty; flip its motor or encoder polarity");
    return;
  }
  for (const auto& [dir, fit] : {std::pair<const char*, const LineFit*>{"forward", &w.forward},
                                 std::pair<const char*, const LineFit*>{"backward", &w.backward}}) {
    std::ostringstream s;
    if (!fit->fitted) {
      s << dir << " line not fitted (" << fit->samples << " samples, need " << o.min_samples << ")";
      say(s.str());
      continue;
    }
    if (std::abs(fit->line.slope) > o.max_abs_slope || std::abs(fit->line.punch) > o.max_abs_punch) {
      s << dir << " slope " << fit->line.slope << " / punch " << fit->line.punch << " beyond the limits ("
        << o.max_abs_slope << " / " << o.max_abs_punch << ")";
      say(s.str());
    }
    if (fit->line.slope <= 0) say(std::string(dir) + " slope is not positive");
  }
}

}  // namespace

MotorFitReport FitMotorCalibration(const std::vector<MotorSample>& left, const std::vector<MotorSample>& right,
                                   const MotorFitOptions& options) {
  MotorFitReport r;
  r.left = FitWheel(left, options.left_motor_polarity, options.left_encoder_polarity, options, &r.calibration.left);
  r.right =
      FitWheel(right, options.right_motor_polarity, options.right_encoder_polarity, options, &r.calibration.right);
  Check("left", r.left, options, &r.problems);
  Check("right", r.right, options, &r.problems);
  r.acceptable = r.problems.empty();
  return r;
}

void SettledMotorSamples::OnDuty(int64_t t, double left, double right) {
  const double d[2] = {left, right};
  for (int w = 0; w < 2; ++w) {
    if (!duty_known_[w] || std::abs(d[w] - duty_[w]) > duty_tolerance_) duty_since_[w] = t;
    duty_[w] = d[w];
    duty_known_[w] = true;
  }
}

void SettledMotorSamples::OnWheelSpeeds(int64_t t, double left, double right) { Add(t, left, right, measured_); }

void SettledMotorSamples::OnEncoderTicks(int64_t t, int64_t left, int64_t right, int64_t delta_time_us) {
  if (have_ticks_) {
    const double dt = delta_time_us > 0 ? delta_time_us * 1e-6 : (t - ticks_t_) * 1e-6;
    if (dt > 0) {
      const double k = rad_per_tick_ / dt;
      Add(t, k * (left - left_ticks_), k * (right - right_ticks_), from_encoders_);
    }
  }
  have_ticks_ = true;
  ticks_t_ = t, left_ticks_ = left, right_ticks_ = right;
}

void SettledMotorSamples::Add(int64_t t, double left_speed, double right_speed, std::vector<MotorSample>* out) {
  const double s[2] = {left_speed, right_speed};
  for (int w = 0; w < 2; ++w) {
    if (!duty_known_[w] || !std::isfinite(s[w])) continue;
    if ((t - duty_since_[w]) * 1e-6 < settle_s_) continue;
    out[w].push_back({duty_[w], s[w]});
  }
}

}  // namespace mbot::motion
