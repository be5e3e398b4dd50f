#include "mbot/mapping/scan_matching.hpp"

#include <ceres/ceres.h>
#include <ceres/cubic_interpolation.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mbot::mapping {

std::vector<Point2> ScanHitPoints(const std::vector<ScanRay>& rays, double min_spacing_m) {
  std::vector<Point2> out;
  out.reserve(rays.size());
  const float min_sq = static_cast<float>(min_spacing_m * min_spacing_m);
  for (const ScanRay& r : rays) {
    if (!r.hit || !std::isfinite(r.ex) || !std::isfinite(r.ey)) continue;
    if (!out.empty() && min_sq > 0) {
      const float dx = r.ex - out.back().x, dy = r.ey - out.back().y;
      if (dx * dx + dy * dy < min_sq) continue;
    }
    out.push_back({r.ex, r.ey});
  }
  return out;
}

MatchGrid::MatchGrid(const OccupancyGrid& grid, double sigma_m, int occupied_threshold, int levels)
    : width_(grid.width()),
      height_(grid.height()),
      resolution_(grid.resolution()),
      origin_x_(grid.origin_x()),
      origin_y_(grid.origin_y()) {
  if (levels < 1 || levels > 12) throw std::invalid_argument("match grid: levels must be 1..12");
  if (!(sigma_m > 0)) throw std::invalid_argument("match grid: sigma must be positive");
  const size_t n = static_cast<size_t>(width_) * height_;
  // The field is exp(-d²/2σ²) of the distance to the nearest obstacle, which rounds to 0 at 8 bits
  // a few σ out: each obstacle cell stamps its kernel (the maximum wins), which on a submap's sparse
  // walls is far cheaper than a distance transform of the whole grid.
  const double k = -resolution_ * resolution_ / (2.0 * sigma_m * sigma_m);
  const int reach = static_cast<int>(std::ceil(std::sqrt(std::log(512.0) / -k)));
  const int side = 2 * reach + 1;
  std::vector<uint8_t> kernel(static_cast<size_t>(side) * side);
  for (int dy = -reach; dy <= reach; ++dy) {
    for (int dx = -reach; dx <= reach; ++dx) {
      kernel[static_cast<size_t>(dy + reach) * side + (dx + reach)] =
          static_cast<uint8_t>(std::lround(255.0 * std::exp(k * (dx * dx + dy * dy))));
    }
  }
  levels_.resize(levels);
  std::vector<uint8_t>& field = levels_[0];
  field.assign(n, 0);
  const std::vector<int8_t>& cells = grid.cells();
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x) {
      if (cells[static_cast<size_t>(y) * width_ + x] <= occupied_threshold) continue;
      const int x0 = std::max(0, x - reach), x1 = std::min(width_ - 1, x + reach);
      const int y0 = std::max(0, y - reach), y1 = std::min(height_ - 1, y + reach);
      for (int yy = y0; yy <= y1; ++yy) {
        uint8_t* row = &field[static_cast<size_t>(yy) * width_];
        const uint8_t* kr = &kernel[static_cast<size_t>(yy - y + reach) * side + (reach - x)];
        for (int xx = x0; xx <= x1; ++xx) row[xx] = std::max(row[xx], kr[xx]);
      }
    }
  }
  std::vector<uint8_t> rows;
  for (int h = 1; h < levels; ++h) {
    // Block maximum over 2^h × 2^h from two half blocks per axis: rows first, then columns.
    const int s = 1 << (h - 1), pad = (1 << h) - 1, w = width_ + pad, hh = height_ + pad;
    rows.assign(static_cast<size_t>(w) * (height_ + s - 1), 0);  // x over level h, y over level h − 1
    const int pad_prev = s - 1;
    for (int y = -pad_prev; y < height_; ++y) {
      for (int x = -pad; x < width_; ++x) {
        rows[static_cast<size_t>(y + pad_prev) * w + (x + pad)] =
            static_cast<uint8_t>(std::max(Bound(h - 1, x, y), Bound(h - 1, x + s, y)));
      }
    }
    auto row_at = [&](int x, int y) -> int {
      const int yy = y + pad_prev;
      return yy >= 0 && yy < height_ + s - 1 ? rows[static_cast<size_t>(yy) * w + (x + pad)] : 0;
    };
    std::vector<uint8_t>& out = levels_[h];
    out.assign(static_cast<size_t>(w) * hh, 0);
    for (int y = -pad; y < height_; ++y) {
      for (int x = -pad; x < width_; ++x) {
        out[static_cast<size_t>(y + pad) * w + (x + pad)] =
            static_cast<uint8_t>(std::max(row_at(x, y), row_at(x, y + s)));
      }
    }
  }
}

double MatchGrid::Score(const motion::Pose2D& pose, const std::vector<Point2>& points) const {
  if (points.empty()) return 0.0;
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  double sum = 0;
  for (const Point2& p : points) {
    const double x = pose.x + c * p.x - s * p.y, y = pose.y + s * p.x + c * p.y;
    sum += At(static_cast<int>(std::floor((x - origin_x_) / resolution_)),
              static_cast<int>(std::floor((y - origin_y_) / resolution_)));
  }
  return sum / points.size();
}

TranslationConstraint ScanTranslationConstraint(const std::vector<Point2>& points, double theta) {
  TranslationConstraint out;
  Eigen::Matrix2d h = Eigen::Matrix2d::Zero();
  int used = 0;
  // Each point's normal: the direction of least spread of its neighbours along the scan within
  // kRadius (up to kReach points either way), so that range noise does not tilt it.
  constexpr double kRadius = 0.25;
  constexpr int kReach = 6, kMinNeighbours = 3;
  const int n = static_cast<int>(points.size());
  for (int i = 0; i < n; ++i) {
    const Point2& p = points[i];
    double sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
    int count = 0;
    for (int j = std::max(0, i - kReach); j <= std::min(n - 1, i + kReach); ++j) {
      const double dx = points[j].x - p.x, dy = points[j].y - p.y;
      if (dx * dx + dy * dy > kRadius * kRadius) continue;
      sx += dx, sy += dy, sxx += dx * dx, sxy += dx * dy, syy += dy * dy;
      ++count;
    }
    if (count < kMinNeighbours) continue;  // an isolated return: no surface to take a direction from
    Eigen::Matrix2d c;
    c << sxx - sx * sx / count, sxy - sx * sy / count, sxy - sx * sy / count, syy - sy * sy / count;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> local(c);
    const Eigen::Vector2d normal = local.eigenvectors().col(0);
    h += normal * normal.transpose();
    ++used;
  }
  if (used < 2) return out;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(h / used);
  out.weak = eig.eigenvalues()[0];
  out.strong = eig.eigenvalues()[1];
  out.weak_axis_rad = motion::WrapAngle(theta + std::atan2(eig.eigenvectors()(1, 0), eig.eigenvectors()(0, 0)));
  return out;
}

MatchResult GlobalMatch(const OccupancyGrid& map, const std::vector<Point2>& points, double sigma_m,
                        int occupied_threshold, double min_score, double min_angular_step_rad) {
  MatchResult best;
  if (points.empty() || map.width() == 0) return best;
  const double half_w = 0.5 * map.width() * map.resolution(), half_h = 0.5 * map.height() * map.resolution();
  const double linear = std::max(half_w, half_h);
  int levels = 1;
  while ((1 << (levels - 1)) < 2 * static_cast<int>(std::ceil(linear / map.resolution())) + 1 && levels < 12) ++levels;
  const MatchGrid grid(map, sigma_m, occupied_threshold, levels);
  const motion::Pose2D centre{map.origin_x() + half_w, map.origin_y() + half_h, 0.0};
  best = MatchBranchAndBound(grid, points, centre, SearchWindow{linear, M_PI, min_angular_step_rad}, min_score);
  if (best.found) {
    best.pose = RefineMatch(grid, points, best.pose, RefineOptions{});
    best.pose.theta = motion::WrapAngle(best.pose.theta);
    best.score = grid.Score(best.pose, points);
  }
  return best;
}

size_t MatchGrid::bytes() const {
  size_t b = 0;
  for (const auto& l : levels_) b += l.size();
  return b;
}

namespace {

struct Candidate {
  int angle = 0, dx = 0, dy = 0;
  int64_t score = 0;
};

bool BestFirst(const Candidate& a, const Candidate& b) { return a.score > b.score; }

class BranchAndBound {
 public:
  BranchAndBound(const MatchGrid& grid, const std::vector<std::vector<int>>& cells, int window_cells)
      : grid_(grid), cells_(cells), window_(window_cells) {}

  int64_t ScoreAt(int h, const Candidate& c) {
    ++evaluated_;
    const std::vector<int>& xy = cells_[c.angle];
    int64_t sum = 0;
    for (size_t i = 0; i < xy.size(); i += 2) sum += grid_.Bound(h, xy[i] + c.dx, xy[i + 1] + c.dy);
    return sum;
  }

  // Depth-first over `candidates` (sorted best first) at level h; raises best_ when a leaf beats it.
  void Search(std::vector<Candidate>& candidates, int h) {
    for (const Candidate& c : candidates) {
      if (c.score <= best_.score) break;
      if (h == 0) {
        best_ = c;
        break;
      }
      const int s = 1 << (h - 1);
      std::vector<Candidate> children;
      children.reserve(4);
      for (int ox : {0, s}) {
        for (int oy : {0, s}) {
          Candidate child{c.angle, c.dx + ox, c.dy + oy, 0};
          if (child.dx > window_ || child.dy > window_) continue;
          child.score = ScoreAt(h - 1, child);
          children.push_back(child);
        }
      }
      std::sort(children.begin(), children.end(), BestFirst);
      Search(children, h - 1);
    }
  }

  Candidate best_;
  int64_t evaluated_ = 0;

 private:
  const MatchGrid& grid_;
  const std::vector<std::vector<int>>& cells_;
  int window_;
};

}  // namespace

MatchResult MatchBranchAndBound(const MatchGrid& grid, const std::vector<Point2>& points, const motion::Pose2D& initial,
                                const SearchWindow& window, double min_score) {
  MatchResult result;
  if (grid.empty() || points.empty()) return result;
  const double res = grid.resolution();
  double max_range = res;
  for (const Point2& p : points) max_range = std::max(max_range, std::hypot(double(p.x), double(p.y)));
  double step = std::acos(std::clamp(1.0 - res * res / (2.0 * max_range * max_range), -1.0, 1.0));
  step = std::max(step, window.min_angular_step_rad);
  const int n_angles = window.angular_rad > 0 ? static_cast<int>(std::ceil(window.angular_rad / step)) : 0;
  const int wl = static_cast<int>(std::ceil(window.linear_m / res));
  // The scan at every angle, as cells around `initial`'s position.
  std::vector<std::vector<int>> cells(2 * n_angles + 1);
  std::vector<double> angles(cells.size());
  for (int a = 0; a < static_cast<int>(cells.size()); ++a) {
    angles[a] = initial.theta + (a - n_angles) * step;
    const double c = std::cos(angles[a]), s = std::sin(angles[a]);
    std::vector<int>& xy = cells[a];
    xy.reserve(points.size() * 2);
    for (const Point2& p : points) {
      xy.push_back(static_cast<int>(std::floor((initial.x + c * p.x - s * p.y - grid.origin_x()) / res)));
      xy.push_back(static_cast<int>(std::floor((initial.y + s * p.x + c * p.y - grid.origin_y()) / res)));
    }
  }
  int top = 0;
  while (top + 1 < grid.levels() && (1 << top) < 2 * wl + 1) ++top;
  BranchAndBound bb(grid, cells, wl);
  std::vector<Candidate> candidates;
  for (int a = 0; a < static_cast<int>(cells.size()); ++a) {
    for (int dx = -wl; dx <= wl; dx += 1 << top) {
      for (int dy = -wl; dy <= wl; dy += 1 << top) {
        Candidate c{a, dx, dy, 0};
        c.score = bb.ScoreAt(top, c);
        candidates.push_back(c);
      }
    }
  }
  std::sort(candidates.begin(), candidates.end(), BestFirst);
  // Scores are sums of 8-bit field values: the bar is min_score of the most the points can sum to.
  bb.best_.score = static_cast<int64_t>(std::ceil(min_score * 255.0 * points.size())) - 1;
  bb.Search(candidates, top);
  result.evaluated = bb.evaluated_;
  if (bb.best_.score < static_cast<int64_t>(std::ceil(min_score * 255.0 * points.size()))) return result;
  result.found = true;
  result.pose = {initial.x + bb.best_.dx * res, initial.y + bb.best_.dy * res,
                 motion::WrapAngle(angles[bb.best_.angle])};
  result.score = bb.best_.score / (255.0 * points.size());
  return result;
}

namespace {

// The field as Ceres' interpolator reads it: row = y, column = x, 0 off the grid.
struct FieldAdapter {
  enum { DATA_DIMENSION = 1 };
  const MatchGrid* grid;
  void GetValue(int row, int col, double* f) const { *f = grid->At(col, row); }
};

struct OccupiedSpaceCost {
  static constexpr double kEpsilon = 1e-3;
  OccupiedSpaceCost(const MatchGrid& grid, const std::vector<Point2>& points, double weight)
      : adapter_{&grid}, interpolator_(adapter_), grid_(grid), points_(points), weight_(weight) {}

  template <typename T>
  bool operator()(const T* const pose, T* residual) const {
    using std::cos;
    using std::sin;
    using std::sqrt;
    const T c = cos(pose[2]), s = sin(pose[2]);
    const double inv_res = 1.0 / grid_.resolution();
    for (size_t i = 0; i < points_.size(); ++i) {
      const T x = pose[0] + c * double(points_[i].x) - s * double(points_[i].y);
      const T y = pose[1] + s * double(points_[i].x) + c * double(points_[i].y);
      // Cell centres sit at integer coordinates.
      const T col = (x - grid_.origin_x()) * inv_res - 0.5, row = (y - grid_.origin_y()) * inv_res - 0.5;
      T v;
      interpolator_.Evaluate(row, col, &v);
      // 1 − v grows with the square of the distance near a wall (v is a Gaussian of it), which would
      // make the fit's pull vanish just where it should settle the last centimetres; its square root
      // grows with the distance itself (ε keeps the derivative finite on the wall).
      T u = 1.0 - v;
      if (u < T(0.0)) u = T(0.0);
      residual[i] = weight_ * (sqrt(u + kEpsilon) - std::sqrt(kEpsilon));
    }
    return true;
  }

  FieldAdapter adapter_;
  ceres::BiCubicInterpolator<FieldAdapter> interpolator_;
  const MatchGrid& grid_;
  const std::vector<Point2>& points_;
  double weight_;
};

struct PriorCost {
  PriorCost(const motion::Pose2D& target, double translation_weight, double rotation_weight)
      : target_(target), wt_(translation_weight), wr_(rotation_weight) {}
  template <typename T>
  bool operator()(const T* const pose, T* residual) const {
    residual[0] = wt_ * (pose[0] - target_.x);
    residual[1] = wt_ * (pose[1] - target_.y);
    residual[2] = wr_ * (pose[2] - target_.theta);
    return true;
  }
  motion::Pose2D target_;
  double wt_, wr_;
};

}  // namespace

motion::Pose2D RefineMatch(const MatchGrid& grid, const std::vector<Point2>& points, const motion::Pose2D& initial,
                           const RefineOptions& options) {
  if (grid.empty() || points.empty()) return initial;
  double pose[3] = {initial.x, initial.y, initial.theta};
  ceres::Problem::Options problem_options;
  ceres::Problem problem(problem_options);
  auto* fit = new OccupiedSpaceCost(grid, points, options.occupied_weight / std::sqrt(double(points.size())));
  problem.AddResidualBlock(
      new ceres::AutoDiffCostFunction<OccupiedSpaceCost, ceres::DYNAMIC, 3>(fit, static_cast<int>(points.size())),
      nullptr, pose);
  problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PriorCost, 3, 3>(
                               new PriorCost(initial, options.translation_weight, options.rotation_weight)),
                           nullptr, pose);
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.max_num_iterations = options.max_iterations;
  solver.num_threads = 1;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  return {pose[0], pose[1], motion::WrapAngle(pose[2])};
}

}  // namespace mbot::mapping
