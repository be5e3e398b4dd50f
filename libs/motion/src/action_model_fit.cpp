#include "mbot/motion/action_model_fit.hpp"

#include <ceres/autodiff_first_order_function.h>
#include <ceres/gradient_problem.h>
#include <ceres/gradient_problem_solver.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace mbot::motion {
namespace {

// The same motion expressed with the opposite driving direction.
OdometryStep Reversed(const OdometryStep& s) { return {WrapAngle(s.rot1 + M_PI), -s.trans, WrapAngle(s.rot2 - M_PI)}; }

bool Finite(const Pose2D& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.theta); }

// One Gaussian residual r ~ N(0, s) with variance s = k[param]·magnitude + floor_var.
struct Term {
  int param;  // 0: k1, 1: k2
  double r, magnitude, floor_var;
};

// NLL(a) = Σ 0.5·(r²/s + log s) with k = exp(a), so k stays > 0 without bounds (the gradient
// solver has none) and the problem is well scaled whatever the magnitude of k.
struct NegLogLikelihood {
  const std::vector<Term>* terms;
  template <typename T>
  bool operator()(const T* a, T* cost) const {
    using std::exp;
    using std::log;
    const T k[2] = {exp(a[0]), exp(a[1])};
    *cost = T(0.0);
    for (const Term& t : *terms) {
      const T s = k[t.param] * t.magnitude + t.floor_var;
      *cost += 0.5 * (t.r * t.r / s + log(s));
    }
    return true;
  }
};

void AddNote(std::string* message, const std::string& note) {
  if (!message->empty()) *message += "; ";
  *message += note;
}

}  // namespace

ActionModelFit FitActionModel(const std::vector<Pose2D>& odometry, const std::vector<Pose2D>& truth,
                              const ActionModelFitOptions& options) {
  ActionModelFit fit;
  const int w = options.window_steps;
  if (w < 1 || !(options.min_sigma_rot_rad > 0) || !(options.min_sigma_trans_m > 0) || !(options.initial_k1 > 0) ||
      !(options.initial_k2 > 0) || !std::isfinite(options.initial_k1) || !std::isfinite(options.initial_k2)) {
    fit.message = "invalid options: need window_steps >= 1, noise floors > 0 and finite initial k > 0";
    return fit;
  }
  if (odometry.size() != truth.size()) {
    fit.message = "odometry and truth differ in length (" + std::to_string(odometry.size()) + " vs " +
                  std::to_string(truth.size()) + ")";
    return fit;
  }
  if (odometry.size() < static_cast<size_t>(w) + 1) {
    fit.message = "too short: " + std::to_string(odometry.size()) + " samples, a window needs " + std::to_string(w + 1);
    return fit;
  }

  const double floor_rot = options.min_sigma_rot_rad * options.min_sigma_rot_rad;
  const double floor_trans = options.min_sigma_trans_m * options.min_sigma_trans_m;
  std::vector<Term> terms;
  int non_finite = 0, translating = 0;
  for (size_t i = 0; i + w < odometry.size(); i += w) {
    const Pose2D &o0 = odometry[i], &o1 = odometry[i + w], &t0 = truth[i], &t1 = truth[i + w];
    if (!Finite(o0) || !Finite(o1) || !Finite(t0) || !Finite(t1)) {
      ++non_finite;
      ++fit.windows_skipped;
      continue;
    }
    const double odo_dist = std::hypot(o1.x - o0.x, o1.y - o0.y);
    const double odo_turn = WrapAngle(o1.theta - o0.theta);
    if (odo_dist < options.min_trans_m && std::abs(odo_turn) < options.min_rot_rad) {
      ++fit.windows_skipped;
      continue;
    }
    ++fit.windows_used;
    if (odo_dist < options.min_trans_m || std::hypot(t1.x - t0.x, t1.y - t0.y) < options.min_trans_m) {
      // Direction of travel unobservable: only the heading change, as rot1 = 0, rot2 = Δθ.
      const double r = WrapAngle(WrapAngle(t1.theta - t0.theta) - odo_turn);
      terms.push_back({0, r, std::abs(odo_turn), 2 * floor_rot});
      continue;
    }
    ++translating;
    const OdometryStep o = OdometryStepBetween(o0, o1);
    OdometryStep t = OdometryStepBetween(t0, t1);
    // Compare in odometry's driving direction, so noise that flips the canonical sign of the
    // true step does not show up as a half-turn error.
    if ((o.trans < 0) != (t.trans < 0)) t = Reversed(t);
    terms.push_back({0, WrapAngle(t.rot1 - o.rot1), std::abs(o.rot1), floor_rot});
    terms.push_back({1, t.trans - o.trans, std::abs(o.trans), floor_trans});
    terms.push_back({0, WrapAngle(t.rot2 - o.rot2), std::abs(o.rot2), floor_rot});
  }
  if (non_finite > 0) AddNote(&fit.message, std::to_string(non_finite) + " windows with non-finite poses skipped");
  if (fit.windows_used == 0) {
    AddNote(&fit.message, "no usable window: the odometry never moved " + std::to_string(options.min_trans_m) +
                              " m or turned " + std::to_string(options.min_rot_rad) + " rad within " +
                              std::to_string(w) + " samples");
    return fit;
  }
  if (fit.windows_used < options.warn_below_windows) {
    AddNote(&fit.message, "only " + std::to_string(fit.windows_used) + " usable windows: estimates are rough");
  }

  double a[2] = {std::log(options.initial_k1), std::log(options.initial_k2)};
  ceres::GradientProblem problem(
      new ceres::AutoDiffFirstOrderFunction<NegLogLikelihood, 2>(new NegLogLikelihood{&terms}));
  ceres::GradientProblemSolver::Options solver_options;
  solver_options.logging_type = ceres::SILENT;
  solver_options.max_num_iterations = 200;
  solver_options.function_tolerance = 1e-12;
  ceres::GradientProblemSolver::Summary summary;
  ceres::Solve(solver_options, problem, a, &summary);

  const double k[2] = {std::exp(a[0]), std::exp(a[1])};
  fit.k1 = k[0];
  fit.k2 = k[1];
  // Observed information: the NLL separates into a k1 part and a k2 part, so its Hessian in
  // (k1, k2) is diagonal: ∂²/∂k² Σ 0.5·(r²/s + log s) = Σ 0.5·m²·(2r²/s³ − 1/s²).
  double hessian[2] = {0, 0};
  fit.nll = 0;
  for (const Term& t : terms) {
    const double s = k[t.param] * t.magnitude + t.floor_var;
    fit.nll += 0.5 * (t.r * t.r / s + std::log(s) + std::log(2 * M_PI));
    hessian[t.param] += 0.5 * t.magnitude * t.magnitude * (2 * t.r * t.r / (s * s * s) - 1 / (s * s));
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  fit.k1_std = hessian[0] > 0 ? 1 / std::sqrt(hessian[0]) : nan;
  fit.k2_std = hessian[1] > 0 ? 1 / std::sqrt(hessian[1]) : nan;

  fit.converged = summary.termination_type == ceres::CONVERGENCE;
  if (!fit.converged) AddNote(&fit.message, "solver did not converge: " + summary.message);
  if (translating == 0) {
    fit.converged = false;
    AddNote(&fit.message, "no window translated " + std::to_string(options.min_trans_m) + " m: k2 is not observable");
  }
  constexpr double kAtZero = 1e-9;  // far below any plausible k; the fit ran towards k = 0
  if (fit.k1 < kAtZero) AddNote(&fit.message, "k1 ~ 0: rotation errors lie within the noise floor");
  if (translating > 0 && fit.k2 < kAtZero)
    AddNote(&fit.message, "k2 ~ 0: translation errors lie within the noise floor");
  return fit;
}

double PlaceOnStamps(std::vector<TimedPose>* series, const std::vector<int64_t>& stamps) {
  if (stamps.empty() || stamps.size() != series->size()) return -1;
  for (int64_t s : stamps) {
    if (s <= 0) return -1;  // a source without stamps: keep the event times
  }
  int64_t offset = std::numeric_limits<int64_t>::max();
  for (size_t i = 0; i < series->size(); ++i) offset = std::min(offset, (*series)[i].t_us - stamps[i]);
  double max_delay = 0;
  for (size_t i = 0; i < series->size(); ++i) {
    max_delay = std::max(max_delay, ((*series)[i].t_us - stamps[i] - offset) * 1e-6);
    (*series)[i].t_us = stamps[i] + offset;
  }
  std::sort(series->begin(), series->end(), [](const TimedPose& a, const TimedPose& b) { return a.t_us < b.t_us; });
  return max_delay;
}

}  // namespace mbot::motion
