#include "mbot/mapping/pose_graph.hpp"

#include <ceres/ceres.h>

#include <chrono>
#include <cmath>

namespace mbot::mapping {
namespace {

template <typename T>
T Wrap(const T& a) {
  using std::atan2;
  using std::cos;
  using std::sin;
  return atan2(sin(a), cos(a));
}

// The error of `b` seen from `a` against the measured relative pose, scaled by the square roots of
// the weights.
struct RelativePoseCost {
  RelativePoseCost(const motion::Pose2D& relative, double translation_weight, double rotation_weight)
      : rel_(relative), wt_(std::sqrt(translation_weight)), wr_(std::sqrt(rotation_weight)) {}

  template <typename T>
  bool operator()(const T* const a, const T* const b, T* residual) const {
    using std::cos;
    using std::sin;
    const T c = cos(a[2]), s = sin(a[2]);
    const T dx = b[0] - a[0], dy = b[1] - a[1];
    residual[0] = wt_ * (c * dx + s * dy - rel_.x);
    residual[1] = wt_ * (-s * dx + c * dy - rel_.y);
    residual[2] = wr_ * Wrap(T(b[2] - a[2] - rel_.theta));
    return true;
  }
  motion::Pose2D rel_;
  double wt_, wr_;
};

}  // namespace

double ConstraintResidual(const PoseConstraint& c, const std::vector<motion::Pose2D>& nodes,
                          const std::vector<motion::Pose2D>& submaps) {
  const motion::Pose2D& a = BetweenNodes(c) ? nodes[c.from] : submaps[c.from];
  const motion::Pose2D& b = nodes[c.to];
  const double pa[3] = {a.x, a.y, a.theta}, pb[3] = {b.x, b.y, b.theta};
  double r[3];
  RelativePoseCost(c.relative, c.translation_weight, c.rotation_weight)(pa, pb, r);
  return std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
}

PoseGraphSummary OptimizePoseGraph(std::vector<motion::Pose2D>* nodes, std::vector<motion::Pose2D>* submaps,
                                   const std::vector<PoseConstraint>& constraints, const PoseGraphOptions& options) {
  PoseGraphSummary summary;
  if (submaps->empty() || nodes->empty()) return summary;
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<double> n(nodes->size() * 3), s(submaps->size() * 3);
  for (size_t i = 0; i < nodes->size(); ++i)
    n[3 * i] = (*nodes)[i].x, n[3 * i + 1] = (*nodes)[i].y, n[3 * i + 2] = (*nodes)[i].theta;
  for (size_t i = 0; i < submaps->size(); ++i)
    s[3 * i] = (*submaps)[i].x, s[3 * i + 1] = (*submaps)[i].y, s[3 * i + 2] = (*submaps)[i].theta;
  ceres::Problem problem;
  for (const PoseConstraint& c : constraints) {
    double* a = BetweenNodes(c) ? &n[3 * c.from] : &s[3 * c.from];
    double* b = &n[3 * c.to];
    ceres::LossFunction* loss =
        c.kind == PoseConstraint::kLoopClosure ? new ceres::HuberLoss(options.huber_scale) : nullptr;
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<RelativePoseCost, 3, 3, 3>(
                                 new RelativePoseCost(c.relative, c.translation_weight, c.rotation_weight)),
                             loss, a, b);
  }
  if (problem.HasParameterBlock(&s[0])) problem.SetParameterBlockConstant(&s[0]);
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver.max_num_iterations = options.max_iterations;
  solver.num_threads = options.threads;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary out;
  ceres::Solve(solver, &problem, &out);
  for (size_t i = 0; i < nodes->size(); ++i) (*nodes)[i] = {n[3 * i], n[3 * i + 1], motion::WrapAngle(n[3 * i + 2])};
  for (size_t i = 0; i < submaps->size(); ++i)
    (*submaps)[i] = {s[3 * i], s[3 * i + 1], motion::WrapAngle(s[3 * i + 2])};
  summary.initial_cost = out.initial_cost;
  summary.final_cost = out.final_cost;
  summary.iterations = static_cast<int>(out.iterations.size());
  for (size_t i = 0; i < constraints.size(); ++i) {
    if (constraints[i].kind != PoseConstraint::kLoopClosure) continue;
    if (ConstraintResidual(constraints[i], *nodes, *submaps) > options.huber_scale)
      summary.rejected.push_back(static_cast<int>(i));
  }
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return summary;
}

}  // namespace mbot::mapping
