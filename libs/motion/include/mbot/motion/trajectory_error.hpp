// Absolute trajectory error of an estimate against ground truth sampled at the same times, per
// axis as in the seed report's Table V: RMSE, mean, max and standard deviation of the absolute
// error in x, y and heading. Two conventions: after the best-fit SE(2) alignment of the estimate
// onto the truth (least squares over positions, Umeyama without scale), or anchored so the first
// poses coincide.
#pragma once

#include <vector>

#include "mbot/motion/pose2d.hpp"

namespace mbot::motion {

enum class AteAlignment { kBestFitSE2, kFirstPose, kNone };  // kNone: the frames already agree

struct ErrorStats {
  double rmse = 0, mean = 0, max = 0, std = 0;  // of the absolute error
};

struct AteResult {
  int samples = 0;
  ErrorStats x, y, theta, xy;  // xy: the Euclidean position error; theta in radians
  Pose2D alignment;            // applied to the estimate: aligned = alignment ⊕ estimate
  Pose2D final_error;          // truth⁻¹-free difference at the last sample: aligned − truth
};

// The rigid transform T minimising Σ |T ⊕ est_i − truth_i|² over positions.
Pose2D BestFitSE2(const std::vector<Pose2D>& estimate, const std::vector<Pose2D>& truth);

// `estimate` and `truth` are paired by index; both must have the same size (≥ 1).
AteResult ComputeAte(const std::vector<Pose2D>& estimate, const std::vector<Pose2D>& truth, AteAlignment alignment);

// An estimate scored against the truth under each convention at once.
struct TrajectoryErrors {
  AteResult aligned, anchored, unaligned;
};
TrajectoryErrors EvaluateTrajectory(const std::vector<Pose2D>& estimate, const std::vector<Pose2D>& truth);

}  // namespace mbot::motion
