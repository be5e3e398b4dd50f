#include "mbot/sim/sim_model_fit.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <map>
#include <memory>
#include <stdexcept>
#include <variant>

namespace mbot::sim {

using msgs::Event;
using msgs::EventKind;

namespace {

constexpr int kParameters = 5;

// The fitted parameters, as log(value): positive by construction, and a step is relative.
// A time constant of 0 (no lag) starts the fit at 1 ms.
std::array<double, kParameters> Read(const SimRobotOptions& r) {
  const auto lag = [](double tau) { return std::log(std::max(tau, 1e-3)); };
  return {std::log(r.left_motor_gain), std::log(r.right_motor_gain), lag(r.motor_time_constant_s),
          lag(r.controller.v_time_constant_s), lag(r.controller.w_time_constant_s)};
}

const char* const kKeys[kParameters] = {"left_motor_gain", "right_motor_gain", "motor_time_constant_s",
                                        "firmware_v_time_constant_s", "firmware_w_time_constant_s"};

SimRobotOptions Apply(SimRobotOptions r, const double* x) {
  r.left_motor_gain = std::exp(x[0]);
  r.right_motor_gain = std::exp(x[1]);
  r.motor_time_constant_s = std::exp(x[2]);
  r.controller.v_time_constant_s = std::exp(x[3]);
  r.controller.w_time_constant_s = std::exp(x[4]);
  return r;
}

// The deterministic part of the model: what the fit compares is the response to the commands.
SimRobotOptions Quiet(SimRobotOptions r) {
  r.slip_stddev = 0;
  r.imu.gyro_noise_rad_s = 0;
  r.imu.gyro_bias_initial_rad_s = 0;
  r.imu.gyro_bias_walk_rad_s_sqrt_s = 0;
  return r;
}

SimFidelityResult Compare(const std::vector<Event>& log, SimFidelityOptions o, double begin_s, double end_s) {
  o.begin_s = begin_s;
  o.end_s = end_s;
  SimFidelity f(o, std::nullopt, 1);
  for (const Event& e : log) f.Add(e);
  return f.Finish();
}

// Every residual of one simulation: per wheel window the two wheels' speed errors, per gyro window
// the yaw-rate error times the base radius (a wheel-speed difference) [m/s].
std::vector<double> Residuals(const SimFidelityResult& r, double base_radius_m) {
  std::vector<double> out;
  out.reserve(2 * r.wheel_windows.size() + r.yaw_windows.size());
  for (const WheelWindow& w : r.wheel_windows)
    out.push_back(w.sim_left - w.real_left), out.push_back(w.sim_right - w.real_right);
  for (const YawWindow& w : r.yaw_windows) out.push_back(base_radius_m * (w.sim - w.real));
  return out;
}

// Whole simulations of the fitted part, by parameter vector: each is shared by all the windows'
// residual blocks (Ceres evaluates them one by one at the same points).
class Simulations {
 public:
  Simulations(const std::vector<Event>& log, SimFidelityOptions base, double split_s, int size)
      : log_(log), base_(std::move(base)), split_s_(split_s), size_(size) {}

  const std::vector<double>& At(const double* x) {
    std::array<double, kParameters> key;
    std::copy(x, x + kParameters, key.begin());
    auto it = cache_.find(key);
    if (it != cache_.end()) return it->second;
    SimFidelityOptions o = base_;
    o.robot = Apply(o.robot, x);
    std::vector<double> r = Residuals(Compare(log_, o, 0.0, split_s_), o.robot.geometry.base_radius_m);
    // The windows are the log's (its encoder and gyro times); a simulation that gives other ones
    // (it cannot, short of a bug) is answered with no residuals, which Evaluate reports as a failure.
    if (static_cast<int>(r.size()) != size_) r.clear();
    if (order_.size() >= 64) cache_.erase(order_.front()), order_.pop_front();
    order_.push_back(key);
    return cache_.emplace(key, std::move(r)).first->second;
  }

 private:
  const std::vector<Event>& log_;
  SimFidelityOptions base_;
  double split_s_;
  int size_;  // residuals per simulation: 2 per wheel window, 1 per gyro window
  std::map<std::array<double, kParameters>, std::vector<double>> cache_;
  std::deque<std::array<double, kParameters>> order_;
};

// One window's residuals (a slice of the simulation's) and their central-difference Jacobian.
class WindowCost : public ceres::CostFunction {
 public:
  WindowCost(Simulations* sims, int offset, int count, double step) : sims_(sims), offset_(offset), step_(step) {
    set_num_residuals(count);
    mutable_parameter_block_sizes()->push_back(kParameters);
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const int n = num_residuals();
    const std::vector<double>& r = sims_->At(parameters[0]);
    if (r.empty()) return false;
    std::copy(r.begin() + offset_, r.begin() + offset_ + n, residuals);
    if (jacobians == nullptr || jacobians[0] == nullptr) return true;
    std::array<double, kParameters> x;
    std::copy(parameters[0], parameters[0] + kParameters, x.begin());
    for (int j = 0; j < kParameters; ++j) {
      const double keep = x[j];
      x[j] = keep + step_;
      const std::vector<double>& at_plus = sims_->At(x.data());
      if (at_plus.empty()) return false;
      const std::vector<double> plus(at_plus.begin() + offset_, at_plus.begin() + offset_ + n);
      x[j] = keep - step_;
      const std::vector<double>& minus = sims_->At(x.data());
      if (minus.empty()) return false;
      for (int i = 0; i < n; ++i)
        jacobians[0][i * kParameters + j] =
            (plus[static_cast<size_t>(i)] - minus[static_cast<size_t>(offset_ + i)]) / (2 * step_);
      x[j] = keep;
    }
    return true;
  }

 private:
  Simulations* sims_;
  int offset_;
  double step_;
};

double Median(std::vector<double> v) {
  if (v.empty()) return NAN;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

int64_t FirstTruth(const std::vector<Event>& log) {
  for (const Event& e : log)
    if (e.kind == EventKind::kGroundTruth) return e.t_us;
  throw std::runtime_error("sim_model_fit: the log has no motion capture (TRUE_POSE)");
}

}  // namespace

bool WheelsTurned(const std::vector<Event>& log) {
  bool have = false;
  int64_t left = 0, right = 0;
  for (const Event& e : log) {
    if (e.kind != EventKind::kEncoders) continue;
    const auto& k = std::get<msgs::EncoderTicks>(e.payload);
    if (have && (k.left_ticks != left || k.right_ticks != right)) return true;
    have = true, left = k.left_ticks, right = k.right_ticks;
  }
  return false;
}

double MotionMidpoint(const std::vector<Event>& log) {
  const int64_t t0 = FirstTruth(log);
  std::vector<std::pair<int64_t, double>> turned;  // (time, the wheels' rotation so far [ticks])
  bool have = false;
  int64_t left = 0, right = 0;
  double total = 0;
  for (const Event& e : log) {
    if (e.kind != EventKind::kEncoders || e.t_us < t0) continue;
    const auto& k = std::get<msgs::EncoderTicks>(e.payload);
    if (have) total += std::llabs(k.left_ticks - left) + std::llabs(k.right_ticks - right);
    have = true, left = k.left_ticks, right = k.right_ticks;
    turned.emplace_back(e.t_us, total);
  }
  for (const auto& [t, so_far] : turned)
    if (total > 0 && so_far >= 0.5 * total) return (t - t0) * 1e-6;
  throw std::runtime_error("sim_model_fit: the wheels did not turn after the first motion-capture pose");
}

std::vector<std::pair<double, double>> FindStandstills(const std::vector<Event>& log, double min_s) {
  const int64_t t0 = FirstTruth(log);
  std::vector<std::pair<double, double>> out;
  bool have = false;
  int64_t start = 0, last = 0, left = 0, right = 0;
  const auto close = [&] {
    if (have && (last - start) * 1e-6 >= min_s) out.emplace_back((start - t0) * 1e-6, (last - start) * 1e-6);
  };
  for (const Event& e : log) {
    if (e.kind != EventKind::kEncoders) continue;
    const auto& k = std::get<msgs::EncoderTicks>(e.payload);
    if (have && k.left_ticks == left && k.right_ticks == right) {
      last = e.t_us;
      continue;
    }
    close();
    have = true;
    start = last = e.t_us;
    left = k.left_ticks, right = k.right_ticks;
  }
  close();
  return out;
}

SensorNoiseEstimate EstimateSensorNoise(const std::vector<Event>& log, const SimFidelityOptions& o,
                                        double min_standstill_s) {
  SensorNoiseEstimate n;
  const int64_t t0 = FirstTruth(log);
  const auto still = FindStandstills(log, min_standstill_s);
  // The standstill a time [s from t0] lies in, with a margin at both ends; -1: none.
  const auto in_still = [&](double t, double margin) {
    for (size_t k = 0; k < still.size(); ++k)
      if (t >= still[k].first + margin && t <= still[k].first + still[k].second - margin) return static_cast<int>(k);
    return -1;
  };
  double sum = 0, sq = 0;
  long long none = 0;
  // Ranges per standstill and direction (bins of 0.25°).
  std::map<std::pair<int, int>, std::vector<double>> ranges;
  for (const Event& e : log) {
    const double t = (e.t_us - t0) * 1e-6;
    if (e.kind == EventKind::kImu) {
      if (in_still(t, 0.1) < 0) continue;
      const double g = std::get<msgs::Imu>(e.payload).gyro_rad_s[2] * o.gyro_scale;
      sum += g, sq += g * g, ++n.gyro_samples;
    } else if (e.kind == EventKind::kLidar) {
      const auto& s = std::get<msgs::LidarScan>(e.payload);
      const int k = in_still(t, 0.0);
      const double period_s = 1.0 / o.robot.lidar.rate_hz;
      const bool whole = k >= 0 && in_still(t - period_s, 0.0) == k;  // the whole revolution stood
      n.scans += whole;
      for (size_t i = 0; i < s.ranges_m.size() && i < s.angles_rad.size(); ++i) {
        const double r = s.ranges_m[i];
        const bool ok = std::isfinite(r) && r >= o.lidar_min_range_m && r < o.lidar_max_range_m;
        ++n.beams;
        none += !ok;
        if (!ok || !whole) continue;
        const double deg = motion::WrapAngle(s.angles_rad[i]) * 180 / M_PI;
        ranges[{k, static_cast<int>(std::floor(deg / 0.25))}].push_back(r);
      }
    }
  }
  if (n.gyro_samples > 1) {
    n.gyro_bias_rad_s = sum / n.gyro_samples;
    n.gyro_noise_rad_s = std::sqrt(std::max(0.0, (sq - sum * sum / n.gyro_samples) / (n.gyro_samples - 1)));
  }
  if (n.beams > 0) n.no_return_rate = static_cast<double>(none) / n.beams;
  std::vector<double> spreads;
  std::array<std::vector<double>, 4> by_range;  // directions whose median range is in 0-1.5, -3, -4.5, 4.5+ m
  // The standard deviation about each direction's median, without the returns more than 0.1 m off
  // it (another surface); not the MAD: the legacy ranges are quantised to 1 cm, and the MAD of
  // quantised ranges is a whole number of steps.
  for (auto& [key, v] : ranges) {
    if (v.size() < 5) continue;
    const double med = Median(v);
    double sq = 0;
    int used = 0;
    for (double r : v)
      if (std::abs(r - med) <= 0.1) sq += (r - med) * (r - med), ++used;
    if (used >= 5) {
      spreads.push_back(std::sqrt(sq / (used - 1)));
      by_range[std::min(3, static_cast<int>(med / 1.5))].push_back(spreads.back());
    }
  }
  for (int k = 0; k < 4; ++k) n.range_noise_by_range_m[k] = Median(by_range[k]);
  n.range_noise_m = Median(spreads);
  return n;
}

SimModelFitResult FitSimModel(const std::vector<Event>& log, const SimFidelityOptions& base,
                              const SimModelFitOptions& options) {
  SimModelFitResult out;
  const int64_t t0 = FirstTruth(log);
  int64_t t_end = t0;
  for (const Event& e : log)
    if (e.kind == EventKind::kGroundTruth) t_end = std::max(t_end, e.t_us);
  out.duration_s = (t_end - t0) * 1e-6;
  out.split_s = options.split_s;
  if (!std::isfinite(out.split_s)) out.split_s = MotionMidpoint(log);
  SimFidelityOptions quiet = base;
  quiet.robot = Quiet(base.robot);
  out.fit_before = Compare(log, quiet, 0.0, out.split_s);
  out.held_before = Compare(log, quiet, out.split_s, 1e300);
  const auto moved = [](const SimFidelityResult& r) {
    double s = 0;
    for (const WheelWindow& w : r.wheel_windows) s += std::abs(w.real_left) + std::abs(w.real_right);
    return s > 0;
  };
  if (out.fit_before.wheel_windows.empty() || !moved(out.fit_before))
    throw std::runtime_error("sim_model_fit: the robot's wheels did not turn before " + std::to_string(out.split_s) +
                             " s (a standing log fits no motor)");
  if (!moved(out.held_before))
    throw std::runtime_error("sim_model_fit: the robot's wheels did not turn after " + std::to_string(out.split_s) +
                             " s: nothing to hold out");

  std::array<double, kParameters> x = Read(quiet.robot);
  const int wheel = static_cast<int>(out.fit_before.wheel_windows.size());
  const int yaw = static_cast<int>(out.fit_before.yaw_windows.size());
  Simulations sims(log, quiet, out.split_s, 2 * wheel + yaw);
  ceres::Problem problem;
  for (int k = 0; k < wheel; ++k)
    problem.AddResidualBlock(new WindowCost(&sims, 2 * k, 2, options.numeric_step),
                             new ceres::HuberLoss(options.huber_m_s), x.data());
  for (int k = 0; k < yaw; ++k)
    problem.AddResidualBlock(new WindowCost(&sims, 2 * wheel + k, 1, options.numeric_step),
                             new ceres::HuberLoss(options.huber_m_s), x.data());
  out.windows_fit = wheel + yaw;
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = options.max_iterations;
  so.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  out.iterations = static_cast<int>(summary.iterations.size());
  out.initial_cost = summary.initial_cost;
  out.final_cost = summary.final_cost;
  out.termination = ceres::TerminationTypeToString(summary.termination_type);

  // 1σ from the Gauss–Newton covariance, scaled by the residuals' own variance (they carry units).
  std::array<double, kParameters * kParameters> cov;
  cov.fill(NAN);
  ceres::Covariance::Options co;
  co.algorithm_type = ceres::DENSE_SVD;
  co.null_space_rank = -1;
  ceres::Covariance covariance(co);
  std::vector<std::pair<const double*, const double*>> blocks = {{x.data(), x.data()}};
  const int dof = std::max(1, summary.num_residuals - kParameters);
  const double s2 = 2 * summary.final_cost / dof;
  if (covariance.Compute(blocks, &problem)) covariance.GetCovarianceBlock(x.data(), x.data(), cov.data());

  out.fitted = Apply(base.robot, x.data());
  const std::array<double, kParameters> before = Read(base.robot);
  for (int j = 0; j < kParameters; ++j) {
    const double value = std::exp(x[j]);
    out.parameters.push_back({kKeys[j], std::exp(before[j]), value, value * std::sqrt(cov[j * kParameters + j] * s2)});
  }
  SimFidelityOptions fitted = quiet;
  fitted.robot = Quiet(out.fitted);
  out.fit_after = Compare(log, fitted, 0.0, out.split_s);
  out.held_after = Compare(log, fitted, out.split_s, 1e300);
  return out;
}

}  // namespace mbot::sim
