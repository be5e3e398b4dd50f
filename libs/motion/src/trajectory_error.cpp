#include "mbot/motion/trajectory_error.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mbot::motion {

void AteAccumulator::AddForAlignment(const Pose2D& est, const Pose2D& truth) {
  if (n_ == 0) first_est_ = est, first_truth_ = truth;
  ++n_;
  ex_ += est.x, ey_ += est.y, tx_ += truth.x, ty_ += truth.y;
  dot_ += est.x * truth.x + est.y * truth.y;    // Σ a·b
  cross_ += est.x * truth.y - est.y * truth.x;  // Σ a×b
  tt_ += truth.x * truth.x + truth.y * truth.y;
  sin_ += std::sin(truth.theta - est.theta);
  cos_ += std::cos(truth.theta - est.theta);
  alignment_pose_.reset();
}

Pose2D AteAccumulator::Alignment() const {
  if (alignment_ == AteAlignment::kNone) return {};
  if (n_ == 0) throw std::invalid_argument("ComputeAte: needs paired, non-empty series");
  if (alignment_pose_) return *alignment_pose_;
  if (alignment_ == AteAlignment::kFirstPose) return *(alignment_pose_ = first_truth_.Compose(first_est_.Inverse()));
  const double n = static_cast<double>(n_);
  const double ex = ex_ / n, ey = ey_ / n, tx = tx_ / n, ty = ty_ / n;
  // The centred sums from the raw ones: Σ (a − ā)·(b − b̄) = Σ a·b − n ā·b̄, and so on.
  const double sxx = dot_ - n * (ex * tx + ey * ty), sxy = cross_ - n * (ex * ty - ey * tx);
  const double spread = std::sqrt(std::max(0.0, tt_ / n - (tx * tx + ty * ty)));  // RMS distance from the centroid
  double theta = std::atan2(sxy, sxx);
  // Positions (a robot standing still) fix no rotation: the mean heading offset instead.
  if (n_ == 1 || spread < 0.05) theta = std::atan2(sin_, cos_);
  const double c = std::cos(theta), s = std::sin(theta);
  return *(alignment_pose_ = Pose2D{tx - (c * ex - s * ey), ty - (s * ex + c * ey), theta});
}

void AteAccumulator::Sums::Add(double v) {
  sum += v;
  sq += v * v;
  max = std::max(max, v);
}

ErrorStats AteAccumulator::Sums::Stats(int count) const {
  ErrorStats s;
  const double n = static_cast<double>(count);
  s.max = max;
  s.mean = sum / n;
  s.rmse = std::sqrt(sq / n);
  s.std = std::sqrt(std::max(0.0, sq / n - s.mean * s.mean));
  return s;
}

void AteAccumulator::AddError(const Pose2D& est, const Pose2D& truth) {
  const Pose2D a = Alignment().Compose(est);
  const double dx = a.x - truth.x, dy = a.y - truth.y, dt = WrapAngle(a.theta - truth.theta);
  x_.Add(std::abs(dx));
  y_.Add(std::abs(dy));
  theta_.Add(std::abs(dt));
  xy_.Add(std::hypot(dx, dy));
  final_error_ = {dx, dy, dt};
  ++errors_;
}

AteResult AteAccumulator::Result() const {
  if (errors_ == 0) throw std::invalid_argument("ComputeAte: needs paired, non-empty series");
  AteResult r;
  r.samples = errors_;
  r.alignment = Alignment();
  r.final_error = final_error_;
  r.x = x_.Stats(errors_);
  r.y = y_.Stats(errors_);
  r.theta = theta_.Stats(errors_);
  r.xy = xy_.Stats(errors_);
  return r;
}

Pose2D BestFitSE2(const std::vector<Pose2D>& est, const std::vector<Pose2D>& truth) {
  if (est.empty() || est.size() != truth.size())
    throw std::invalid_argument("BestFitSE2: needs paired, non-empty series");
  AteAccumulator a(AteAlignment::kBestFitSE2);
  for (size_t i = 0; i < est.size(); ++i) a.AddForAlignment(est[i], truth[i]);
  return a.Alignment();
}

AteResult ComputeAte(const std::vector<Pose2D>& est, const std::vector<Pose2D>& truth, AteAlignment alignment) {
  if (est.empty() || est.size() != truth.size())
    throw std::invalid_argument("ComputeAte: needs paired, non-empty series");
  AteAccumulator a(alignment);
  if (alignment != AteAlignment::kNone)
    for (size_t i = 0; i < est.size(); ++i) a.AddForAlignment(est[i], truth[i]);
  for (size_t i = 0; i < est.size(); ++i) a.AddError(est[i], truth[i]);
  return a.Result();
}

TrajectoryErrors EvaluateTrajectory(const std::vector<Pose2D>& estimate, const std::vector<Pose2D>& truth) {
  return {ComputeAte(estimate, truth, AteAlignment::kBestFitSE2), ComputeAte(estimate, truth, AteAlignment::kFirstPose),
          ComputeAte(estimate, truth, AteAlignment::kNone)};
}

}  // namespace mbot::motion
