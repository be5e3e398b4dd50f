#include "mbot/motion/trajectory_error.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mbot::motion {

Pose2D BestFitSE2(const std::vector<Pose2D>& est, const std::vector<Pose2D>& truth) {
  const size_t n = est.size();
  if (n == 0 || n != truth.size()) throw std::invalid_argument("BestFitSE2: needs paired, non-empty series");
  double ex = 0, ey = 0, tx = 0, ty = 0;
  for (size_t i = 0; i < n; ++i) {
    ex += est[i].x;
    ey += est[i].y;
    tx += truth[i].x;
    ty += truth[i].y;
  }
  ex /= n, ey /= n, tx /= n, ty /= n;
  double sxx = 0, sxy = 0;  // Σ a·b and Σ a×b of the centred positions
  for (size_t i = 0; i < n; ++i) {
    const double ax = est[i].x - ex, ay = est[i].y - ey, bx = truth[i].x - tx, by = truth[i].y - ty;
    sxx += ax * bx + ay * by;
    sxy += ax * by - ay * bx;
  }
  double spread = 0;  // RMS distance of the true positions from their centroid
  for (size_t i = 0; i < n; ++i)
    spread += (truth[i].x - tx) * (truth[i].x - tx) + (truth[i].y - ty) * (truth[i].y - ty);
  spread = std::sqrt(spread / n);
  double theta = std::atan2(sxy, sxx);
  if (n == 1 || spread < 0.05) {  // positions (a robot standing still) fix no rotation: use the mean heading offset
    double s = 0, c = 0;
    for (size_t i = 0; i < n; ++i) {
      s += std::sin(truth[i].theta - est[i].theta);
      c += std::cos(truth[i].theta - est[i].theta);
    }
    theta = std::atan2(s, c);
  }
  const double c = std::cos(theta), s = std::sin(theta);
  return {tx - (c * ex - s * ey), ty - (s * ex + c * ey), theta};
}

namespace {
ErrorStats Stats(const std::vector<double>& e) {
  ErrorStats s;
  double sum = 0, sq = 0;
  for (double v : e) {
    sum += v;
    sq += v * v;
    s.max = std::max(s.max, v);
  }
  const double n = static_cast<double>(e.size());
  s.mean = sum / n;
  s.rmse = std::sqrt(sq / n);
  s.std = std::sqrt(std::max(0.0, sq / n - s.mean * s.mean));
  return s;
}
}  // namespace

AteResult ComputeAte(const std::vector<Pose2D>& est, const std::vector<Pose2D>& truth, AteAlignment alignment) {
  if (est.empty() || est.size() != truth.size())
    throw std::invalid_argument("ComputeAte: needs paired, non-empty series");
  AteResult r;
  r.samples = static_cast<int>(est.size());
  if (alignment == AteAlignment::kBestFitSE2)
    r.alignment = BestFitSE2(est, truth);
  else if (alignment == AteAlignment::kFirstPose)
    r.alignment = truth.front().Compose(est.front().Inverse());
  std::vector<double> ex, ey, et, exy;
  for (size_t i = 0; i < est.size(); ++i) {
    const Pose2D a = r.alignment.Compose(est[i]);
    const double dx = a.x - truth[i].x, dy = a.y - truth[i].y, dt = WrapAngle(a.theta - truth[i].theta);
    ex.push_back(std::abs(dx));
    ey.push_back(std::abs(dy));
    et.push_back(std::abs(dt));
    exy.push_back(std::hypot(dx, dy));
    if (i + 1 == est.size()) r.final_error = {dx, dy, dt};
  }
  r.x = Stats(ex);
  r.y = Stats(ey);
  r.theta = Stats(et);
  r.xy = Stats(exy);
  return r;
}

TrajectoryErrors EvaluateTrajectory(const std::vector<Pose2D>& estimate, const std::vector<Pose2D>& truth) {
  return {ComputeAte(estimate, truth, AteAlignment::kBestFitSE2), ComputeAte(estimate, truth, AteAlignment::kFirstPose),
          ComputeAte(estimate, truth, AteAlignment::kNone)};
}

}  // namespace mbot::motion
