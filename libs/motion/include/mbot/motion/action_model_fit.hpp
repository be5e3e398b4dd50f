// Maximum-likelihood calibration of the particle filter's odometry motion model from a log that
// has ground truth. The filter (mbot::mapping::ActionModel) splits each odometry step into
// (rot1, trans, rot2) and assumes the true step differs from it by Gaussian noise with
// σ_rot² = k1·|rot| + floor_rot², σ_trans² = k2·|trans| + floor_trans². Hand-tuned k1, k2 are
// either overconfident (particles collapse and lose the robot) or too diffuse (the map smears);
// fitting them to how odometry actually drifted against the truth gives values with a
// confidence, so two logs or two robots can be compared.
//
// The log is cut into non-overlapping windows of `window_steps` samples (ending where the next
// begins), so the windows' errors are independent, as the likelihood assumes. Each window gives
// the residuals (true − odometry) of rot1, trans, rot2, with σ taken from the odometry step (what
// the filter sees). When the robot translated less than `min_trans_m` in either sequence, the
// direction of travel, hence rot1 vs rot2 and the sign of trans, is not observable: such a window
// contributes only its heading change, modelled as rot1 = 0, rot2 = Δθ (the filter's convention
// for a turn on the spot). Windows that moved less than both thresholds are skipped, as the
// filter does not update on them.
//
// Note the floors enter as σ² = k·|x| + floor² (smooth, so the likelihood is differentiable),
// where the filter uses max(sqrt(k·|x|), floor); the two agree wherever k·|x| ≫ floor².
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mbot/motion/pose2d.hpp"

namespace mbot::motion {

struct ActionModelFitOptions {
  // Samples per window; the odometry step is taken between the window's end samples.
  int window_steps = 10;
  // Noise floors of the model (the filter's ActionModelOptions defaults); fixed, not fitted.
  double min_sigma_rot_rad = 0.002;
  double min_sigma_trans_m = 0.002;
  // A window whose odometry moved less than min_trans_m and turned less than min_rot_rad is
  // skipped; one that translated less than min_trans_m (odometry or truth) is rotation-only.
  double min_trans_m = 0.01;
  double min_rot_rad = 0.02;
  // Starting point of the solver (must be > 0: the fit runs on log k).
  double initial_k1 = 0.01;
  double initial_k2 = 0.01;
  // Fewer usable windows than this still fit, but the message flags the result as rough.
  int warn_below_windows = 10;
};

struct ActionModelFit {
  double k1 = 0.0;      // rotation noise [rad² per rad]
  double k2 = 0.0;      // translation noise [m² per m]
  double k1_std = 0.0;  // 1σ from the inverse Hessian of the NLL at the optimum (NaN if singular)
  double k2_std = 0.0;
  int windows_used = 0;     // windows that contributed residuals
  int windows_skipped = 0;  // windows without motion (or with non-finite poses)
  double nll = 0.0;         // negative log-likelihood at the optimum, including 0.5·log(2π) per residual
  bool converged = false;   // the solver converged and both k were identifiable
  std::string message;      // why not converged, plus warnings (few windows, k at zero); empty if clean
};

// Fits k1, k2 ≥ 0 to `odometry` vs `truth`, which are paired by index (sampled at the same
// times) and must have the same length ≥ window_steps + 1; trailing samples that do not fill a
// window are ignored. Never throws: bad input, invalid options, no usable window, or no window
// that translated (k2 unobservable) return converged = false with the reason in `message`.
// A logger writes messages when they arrive, and a robot's messages can arrive in bursts over a
// second late, while the ground truth is placed on the log clock. Places each sample of `series` at
// its own stamp plus the clock offset of the least-delayed one (min over samples of event time −
// stamp), re-sorted; returns the largest delay removed [s], or -1 (nothing changed) when a sample
// has no stamp (<= 0) or the sizes disagree.
double PlaceOnStamps(std::vector<TimedPose>* series, const std::vector<int64_t>& stamps);

ActionModelFit FitActionModel(const std::vector<Pose2D>& odometry, const std::vector<Pose2D>& truth,
                              const ActionModelFitOptions& options);

}  // namespace mbot::motion
