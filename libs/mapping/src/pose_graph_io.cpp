#include "mbot/mapping/pose_graph_io.hpp"

#include <ceres/ceres.h>

#include <Eigen/Eigenvalues>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

#include "mbot/common/atomic_file.hpp"

namespace mbot::mapping {
namespace {

using motion::Pose2D;

constexpr const char* kSubmapsComment = "# mbot_nav graph SLAM: submaps ";

[[noreturn]] void Fail(const std::string& path, int line, const std::string& what) {
  throw std::runtime_error(path + ":" + std::to_string(line) + ": " + what);
}

std::string Num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

template <typename T>
T Wrap(const T& a) {
  using std::atan2;
  using std::cos;
  using std::sin;
  return atan2(sin(a), cos(a));
}

// g2o's EdgeSE2 error, measurement⁻¹ ⊕ (a⁻¹ ⊕ b), weighted by the information's square root.
struct G2oEdgeCost {
  G2oEdgeCost(const Pose2D& m, const Eigen::Matrix3d& sqrt_info) : m_(m), sqrt_info_(sqrt_info) {}
  template <typename T>
  bool operator()(const T* const a, const T* const b, T* residual) const {
    using std::cos;
    using std::sin;
    const T ca = cos(a[2]), sa = sin(a[2]);
    const T dx = b[0] - a[0], dy = b[1] - a[1];
    const T rx = ca * dx + sa * dy, ry = -sa * dx + ca * dy;  // b in a's frame
    const double cm = std::cos(m_.theta), sm = std::sin(m_.theta);
    T e[3];
    e[0] = cm * (rx - m_.x) + sm * (ry - m_.y);
    e[1] = -sm * (rx - m_.x) + cm * (ry - m_.y);
    e[2] = Wrap(T(b[2] - a[2] - m_.theta));
    for (int i = 0; i < 3; ++i)
      residual[i] = sqrt_info_(i, 0) * e[0] + sqrt_info_(i, 1) * e[1] + sqrt_info_(i, 2) * e[2];
    return true;
  }
  Pose2D m_;
  Eigen::Matrix3d sqrt_info_;
};

Eigen::Matrix3d Information(const G2oEdge& e) {
  const auto& i = e.information;
  Eigen::Matrix3d m;
  m << i[0], i[1], i[2], i[1], i[3], i[4], i[2], i[4], i[5];
  return m;
}

}  // namespace

void WriteG2o(const G2oGraph& graph, const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    if (graph.submaps >= 0)
      out << kSubmapsComment << graph.submaps << " (vertices 0.." << graph.submaps - 1 << "), scan nodes after them\n";
    for (const G2oVertex& v : graph.vertices)
      out << "VERTEX_SE2 " << v.id << ' ' << Num(v.pose.x) << ' ' << Num(v.pose.y) << ' ' << Num(v.pose.theta) << '\n';
    for (int id : graph.fixed) out << "FIX " << id << '\n';
    for (const G2oEdge& e : graph.edges) {
      out << "EDGE_SE2 " << e.from << ' ' << e.to << ' ' << Num(e.relative.x) << ' ' << Num(e.relative.y) << ' '
          << Num(e.relative.theta);
      for (double v : e.information) out << ' ' << Num(v);
      out << '\n';
    }
  });
}

G2oGraph ReadG2o(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open the g2o file");
  G2oGraph g;
  std::unordered_set<int> ids;
  std::string line;
  int line_no = 0;
  std::vector<int> edge_lines;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.size() > 4096) Fail(path, line_no, "line longer than 4096 characters");
    if (line.rfind(kSubmapsComment, 0) == 0) {
      std::istringstream s(line.substr(std::string(kSubmapsComment).size()));
      if (!(s >> g.submaps) || g.submaps < 0) Fail(path, line_no, "bad submap count");
      continue;
    }
    const size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::istringstream s(line);
    std::string tag;
    if (!(s >> tag)) continue;
    std::string rest;
    if (tag == "VERTEX_SE2" || tag == "VERTEX2") {
      G2oVertex v;
      if (!(s >> v.id >> v.pose.x >> v.pose.y >> v.pose.theta)) Fail(path, line_no, tag + ": expected id x y theta");
      if (v.id < 0) Fail(path, line_no, "negative vertex id " + std::to_string(v.id));
      if (!ids.insert(v.id).second) Fail(path, line_no, "vertex " + std::to_string(v.id) + " is defined twice");
      g.vertices.push_back(v);
    } else if (tag == "EDGE_SE2" || tag == "EDGE2") {
      G2oEdge e;
      double m[6];
      if (!(s >> e.from >> e.to >> e.relative.x >> e.relative.y >> e.relative.theta >> m[0] >> m[1] >> m[2] >> m[3] >>
            m[4] >> m[5]))
        Fail(path, line_no, tag + ": expected from to dx dy dtheta and 6 information values");
      if (tag == "EDGE2") {
        e.information = {m[0], m[1], m[4], m[2], m[5], m[3]};  // xx xy yy θθ xθ yθ
      } else {
        e.information = {m[0], m[1], m[2], m[3], m[4], m[5]};
      }
      const auto& i = e.information;
      if (i[0] < 0 || i[3] < 0 || i[5] < 0 || (i[0] == 0 && i[3] == 0 && i[5] == 0))
        Fail(path, line_no, "the information matrix's diagonal must be non-negative and not all zero");
      if (e.from == e.to) Fail(path, line_no, "an edge from vertex " + std::to_string(e.from) + " to itself");
      g.edges.push_back(e);
      edge_lines.push_back(line_no);
    } else if (tag == "FIX") {
      int id;
      if (!(s >> id)) Fail(path, line_no, "FIX: expected a vertex id");
      g.fixed.push_back(id);
      while (s >> id) g.fixed.push_back(id);
    } else {
      Fail(path, line_no, "'" + tag + "' is not an SE(2) pose-graph line (VERTEX_SE2, EDGE_SE2, FIX)");
    }
    if (tag != "FIX" && (s >> rest)) Fail(path, line_no, tag + ": unexpected '" + rest + "' after the values");
  }
  if (in.bad()) throw std::runtime_error(path + ": read error");
  for (size_t k = 0; k < g.edges.size(); ++k) {
    for (int id : {g.edges[k].from, g.edges[k].to})
      if (!ids.count(id))
        Fail(path, edge_lines[k], "the edge names vertex " + std::to_string(id) + ", which is not defined");
  }
  for (int id : g.fixed)
    if (!ids.count(id))
      throw std::runtime_error(path + ": FIX names vertex " + std::to_string(id) + ", which is not defined");
  if (g.submaps > static_cast<int>(g.vertices.size()))
    throw std::runtime_error(path + ": says " + std::to_string(g.submaps) + " submaps but has " +
                             std::to_string(g.vertices.size()) + " vertices");
  return g;
}

G2oGraph ToG2o(const std::vector<Pose2D>& nodes, const std::vector<Pose2D>& submaps,
               const std::vector<PoseConstraint>& constraints) {
  G2oGraph g;
  const int s = static_cast<int>(submaps.size());
  g.submaps = s;
  for (int i = 0; i < s; ++i) g.vertices.push_back({i, submaps[i]});
  for (size_t i = 0; i < nodes.size(); ++i) g.vertices.push_back({s + static_cast<int>(i), nodes[i]});
  if (s > 0) g.fixed.push_back(0);
  for (const PoseConstraint& c : constraints) {
    G2oEdge e;
    e.from = BetweenNodes(c) ? s + c.from : c.from;
    e.to = s + c.to;
    e.relative = c.relative;
    e.information = {c.translation_weight, 0, 0, c.translation_weight, 0, c.rotation_weight};
    g.edges.push_back(e);
  }
  return g;
}

PoseGraphSummary OptimizeG2o(G2oGraph* graph, const PoseGraphOptions& options) {
  PoseGraphSummary summary;
  if (graph->vertices.empty()) return summary;
  const auto t0 = std::chrono::steady_clock::now();
  std::unordered_map<int, size_t> index;
  std::vector<double> p(graph->vertices.size() * 3);
  for (size_t i = 0; i < graph->vertices.size(); ++i) {
    index[graph->vertices[i].id] = i;
    const Pose2D& v = graph->vertices[i].pose;
    p[3 * i] = v.x, p[3 * i + 1] = v.y, p[3 * i + 2] = v.theta;
  }
  ceres::Problem problem;
  for (const G2oEdge& e : graph->edges) {
    const auto a = index.find(e.from), b = index.find(e.to);
    if (a == index.end() || b == index.end())
      throw std::invalid_argument("g2o graph: an edge names a vertex that is not defined");
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(Information(e));
    const Eigen::Vector3d d = eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();
    const Eigen::Matrix3d sqrt_info = d.asDiagonal() * eig.eigenvectors().transpose();
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<G2oEdgeCost, 3, 3, 3>(new G2oEdgeCost(e.relative, sqrt_info)), nullptr,
        &p[3 * a->second], &p[3 * b->second]);
  }
  std::vector<int> fixed = graph->fixed;
  if (fixed.empty()) fixed.push_back(graph->vertices.front().id);
  for (int id : fixed) {
    double* block = &p[3 * index.at(id)];
    if (problem.HasParameterBlock(block)) problem.SetParameterBlockConstant(block);
  }
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver.max_num_iterations = options.max_iterations;
  solver.num_threads = options.threads;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary out;
  ceres::Solve(solver, &problem, &out);
  for (size_t i = 0; i < graph->vertices.size(); ++i)
    graph->vertices[i].pose = {p[3 * i], p[3 * i + 1], motion::WrapAngle(p[3 * i + 2])};
  summary.initial_cost = out.initial_cost;
  summary.final_cost = out.final_cost;
  summary.iterations = static_cast<int>(out.iterations.size());
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return summary;
}

}  // namespace mbot::mapping
