// Absolute trajectory error of an estimate against ground truth sampled at the same times, per
// axis as in the seed report's Table V: RMSE, mean, max and standard deviation of the absolute
// error in x, y and heading. Two conventions: after the best-fit SE(2) alignment of the estimate
// onto the truth (least squares over positions, Umeyama without scale), or anchored so the first
// poses coincide.
#pragma once

#include <optional>
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

// The same scores over pairs that need not fit in memory (a trajectory of hours, read back from
// disk): every pair goes to AddForAlignment, then every pair again, in the same order, to
// AddError; Result() then equals ComputeAte on the whole series. kNone needs no first pass.
class AteAccumulator {
 public:
  explicit AteAccumulator(AteAlignment alignment) : alignment_(alignment) {}
  void AddForAlignment(const Pose2D& estimate, const Pose2D& truth);
  void AddError(const Pose2D& estimate, const Pose2D& truth);
  // The transform applied to the estimate (fixed by the first pass); throws when no pair was added.
  Pose2D Alignment() const;
  int samples() const { return errors_; }
  AteResult Result() const;  // throws std::invalid_argument when no pair was added

 private:
  struct Sums {
    double sum = 0, sq = 0, max = 0;
    void Add(double v);
    ErrorStats Stats(int n) const;
  };
  AteAlignment alignment_;
  // First pass: the sums BestFitSE2 needs (centred cross terms from raw moments) and the first pair.
  long long n_ = 0;
  double ex_ = 0, ey_ = 0, tx_ = 0, ty_ = 0, dot_ = 0, cross_ = 0, tt_ = 0, sin_ = 0, cos_ = 0;
  Pose2D first_est_, first_truth_;
  mutable std::optional<Pose2D> alignment_pose_;
  // Second pass.
  int errors_ = 0;
  Sums x_, y_, theta_, xy_;
  Pose2D final_error_;
};

// An estimate scored against the truth under each convention at once.
struct TrajectoryErrors {
  AteResult aligned, anchored, unaligned;
};
TrajectoryErrors EvaluateTrajectory(const std::vector<Pose2D>& estimate, const std::vector<Pose2D>& truth);

}  // namespace mbot::motion
