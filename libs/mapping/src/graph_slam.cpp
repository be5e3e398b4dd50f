#include "mbot/mapping/graph_slam.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

namespace mbot::mapping {
namespace {

using motion::Pose2D;
using Clock = std::chrono::steady_clock;

double Since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Levels a search over ± `linear_m` needs for its top level to cover the window in one block.
int LevelsFor(double linear_m, double resolution_m) {
  const int width = 2 * static_cast<int>(std::ceil(linear_m / resolution_m)) + 1;
  int levels = 1;
  while ((1 << (levels - 1)) < width && levels < 12) ++levels;
  return levels;
}

// Where `points` (a scan at heading `theta`) pin their position down along one direction only (a
// corridor: weakest over strongest information below `min_ratio`; 0: never), the part of (dx, dy)
// along the corridor, which they cannot tell: (*ax, *ay). Returns whether there is one.
bool AlongCorridor(const std::vector<Point2>& points, double theta, double min_ratio, double dx, double dy, double* ax,
                   double* ay) {
  if (!(min_ratio > 0)) return false;
  const TranslationConstraint tc = ScanTranslationConstraint(points, theta);
  if (tc.ratio() >= min_ratio) return false;
  const double ux = std::cos(tc.weak_axis_rad), uy = std::sin(tc.weak_axis_rad), along = dx * ux + dy * uy;
  *ax = along * ux;
  *ay = along * uy;
  return true;
}

}  // namespace

const MatchGrid& GraphSlam::LoopField::Get() const {
  std::call_once(once_, [&] {
    field_ = std::make_unique<const MatchGrid>(grid_, sigma_m_, threshold_, levels_);
    grid_ = OccupancyGrid();
  });
  return *field_;
}

GraphSlam::GraphSlam(const GraphSlamOptions& options, const MapperOptions& map_options)
    : options_(options), map_options_(map_options), map_(map_options) {
  if (options.nodes_per_submap < 1) throw std::invalid_argument("graph SLAM: nodes_per_submap must be at least 1");
  if (options.optimize_every_nodes < 1)
    throw std::invalid_argument("graph SLAM: optimize_every_nodes must be at least 1");
  if (options.loop_every_nodes < 1) throw std::invalid_argument("graph SLAM: loop_every_nodes must be at least 1");
  if (options.background) worker_ = std::thread(&GraphSlam::WorkerLoop, this);
}

GraphSlam::~GraphSlam() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  if (worker_.joinable()) worker_.join();
}

void GraphSlam::Initialize(const Pose2D& pose, const Pose2D& odometry) {
  correction_ = pose;  // the front end's frame starts at the identity
  last_local_ = Pose2D{};
  last_odometry_ = odometry;
  unmatched_m_ = 0;
  initialized_ = true;
}

Pose2D GraphSlam::ProcessScan(const std::vector<ScanRay>& rays, const Pose2D& odometry, const OdometryDoubt& doubt,
                              double time_s) {
  if (!initialized_) throw std::logic_error("graph SLAM: ProcessScan before Initialize");
  // A doubt holds until a scan is matched: a doubtful scan too sparse to match passes it on.
  const OdometryDoubt held = Merge(unresolved_doubt_, doubt);
  const bool odometry_doubtful = held.doubtful;
  MaybeApplyFinished();
  const auto t0 = Clock::now();
  const Pose2D step = last_odometry_.Inverse().Compose(odometry);
  Pose2D local = last_local_.Compose(step);
  // The odometry's motion since the last scan that was matched: a glitch on a scan too sparse to
  // match is still within reach of the next one's recovery search.
  const double unmatched_m = unmatched_m_ + std::hypot(step.x, step.y);
  bool matched = false, recovered = false;
  auto points = std::make_shared<const std::vector<Point2>>(ScanHitPoints(rays, options_.point_spacing_m));
  ++stats_.scans;
  if (doubt.doubtful) ++doubtful_seen_;
  const bool sparse = static_cast<int>(points->size()) < options_.min_points;
  if (sparse) {
    ++stats_.sparse_scans;
  } else if (!active_.empty()) {
    Submap& s = submaps_[active_.front()];
    if (s.dirty) {
      // The front end's window is a few cells: an exhaustive search of the finest level beats
      // building the coarser ones on every insertion.
      s.field =
          std::make_shared<const MatchGrid>(s.grid->map(), options_.field_sigma_m, options_.occupied_threshold, 1);
      s.wide.reset();
      s.dirty = false;
    }
    Pose2D start = local;
    if (options_.local_search) {
      MatchResult m = MatchBranchAndBound(*s.field, *points, local, options_.local_window, 0.0);
      const bool poor = !m.found || m.score < options_.recover_below * mean_score_;
      if (options_.recover_below > 0 && scores_ >= 20 && (poor || (odometry_doubtful && options_.recover_gap_s > 0))) {
        // The odometry's prior does not fit the map, or the odometry itself is doubtful: look where
        // the robot could be.
        ++stats_.recovery_searches;
        if (!poor) ++stats_.doubtful_searches;
        if (!s.wide) {
          s.wide = std::make_shared<const MatchGrid>(
              s.grid->map(), options_.field_sigma_m, options_.occupied_threshold,
              LevelsFor(options_.recover_window.linear_m, options_.submap.resolution_m));
        }
        // Taken only where it fits as scans usually do, and better than the local answer (by
        // recover_margin of the mean): else that stands. No farther than the odometry since the
        // last matched scan can have been wrong; across an odometry gap, no farther than the robot
        // can have driven by the clock; after a zeroed restart, anywhere in the window.
        const double margin = std::max(options_.recover_margin * mean_score_, 1e-6);
        const double need = std::max(m.found ? m.score + margin : 0.0, options_.recover_below * mean_score_);
        double reach_m = -1.0;
        const double top = top_speed_.Value(), elapsed_s = time_s - matched_time_s_;
        if (odometry_doubtful && options_.recover_speed_factor > 0 && top >= 0 && held.unobserved_s >= 0 &&
            elapsed_s >= 0) {
          reach_m = options_.recover_speed_factor * top * std::max(held.unobserved_s, elapsed_s);
        }
        const SearchWindow window = RecoverySearchWindow(options_, unmatched_m, odometry_doubtful, reach_m);
        if (reach_m >= 0 && window.linear_m < options_.recover_window.linear_m) ++stats_.doubtful_bounded;
        MatchResult w = MatchBranchAndBound(*s.wide, *points, local, window, need);
        // The window is a square and the reach a distance. A best find in a corner beyond the reach
        // says the scan fits best where the robot cannot be: the local answer stands, not the best
        // within reach (a look-alike; Intel with glass and people, seed 2, without the clock bound:
        // 0.0187 m refusing, 0.50 m taking the best within the square the distance holds).
        if (w.found && std::hypot(w.pose.x - local.x, w.pose.y - local.y) > window.linear_m) w.found = false;
        if (w.found) {
          m = w;
          recovered = true;
          ++stats_.recoveries;
          odometry_doubtful_ = true;
          ++doubtful_seen_;
        }
      }
      matched = m.found;
      if (m.found) {
        start = m.pose;
        // A slow running mean (about the last hundred scans).
        mean_score_ = scores_ == 0 ? m.score : mean_score_ + (m.score - mean_score_) / std::min(scores_ + 1, 100);
        ++scores_;
      }
    }
    const Pose2D predicted = local;
    local = RefineMatch(*s.field, *points, start, options_.refine);
    // Where the scan cannot tell how far it moved (a corridor), the match's answer along the
    // corridor is the map's edge, not the motion: odometry's prediction stands there.
    double ax, ay;
    if (AlongCorridor(*points, local.theta, options_.front_min_constraint_ratio, local.x - predicted.x,
                      local.y - predicted.y, &ax, &ay)) {
      local.x -= ax;
      local.y -= ay;
      ++stats_.degenerate_scans;
    }
  }
  last_local_ = local;
  last_odometry_ = odometry;
  unmatched_m_ = matched ? 0.0 : unmatched_m;
  unresolved_doubt_ = matched ? OdometryDoubt{} : held;
  untrusted_since_match_ = untrusted_since_match_ || odometry_doubtful || recovered;
  if (matched && std::isfinite(time_s)) {
    top_speed_.Add(time_s, local, !untrusted_since_match_);
    stats_.top_speed_m_s = top_speed_.Value();
    matched_time_s_ = time_s;
    untrusted_since_match_ = false;
  }
  bool make_node = nodes_.empty();
  if (!make_node && !sparse) {
    const Pose2D moved = nodes_.back().local.Inverse().Compose(local);
    make_node =
        std::hypot(moved.x, moved.y) >= options_.node_distance_m || std::abs(moved.theta) >= options_.node_angle_rad;
  }
  auto shared_rays = std::make_shared<const std::vector<ScanRay>>(rays);
  if (make_node) AddNode(local, odometry, shared_rays, points);
  scans_.push_back({static_cast<int>(nodes_.size()) - 1, nodes_.back().local.Inverse().Compose(local), shared_rays});
  map_.Insert(rays, ToGlobal(local));
  stats_.front_end_s += Since(t0);

  if (nodes_since_solve_ >= options_.optimize_every_nodes) {
    if (options_.background) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!busy_ && !done_) {
        job_ = MakeJob(options_.graph.max_iterations, options_.rerender_map);
        busy_ = true;
        cv_.notify_all();
      }
    } else {
      std::unique_ptr<Job> job = MakeJob(options_.graph.max_iterations, options_.rerender_map);
      RunJob(job.get());
      ApplyJob(job.get());
    }
  }
  return ToGlobal(local);
}

void GraphSlam::AddNode(const Pose2D& local, const Pose2D& odometry, std::shared_ptr<const std::vector<ScanRay>> rays,
                        std::shared_ptr<const std::vector<Point2>> points) {
  const int index = static_cast<int>(nodes_.size());
  auto loop_points = std::make_shared<const std::vector<Point2>>(ScanHitPoints(*rays, options_.loop_point_spacing_m));
  Node n{local, ToGlobal(local), odometry, std::move(rays), std::move(points), std::move(loop_points), {},
         0.0,   doubtful_seen_};
  if (index > 0) {
    const Node& last = nodes_.back();
    n.path_m = last.path_m + std::hypot(local.x - last.local.x, local.y - last.local.y);
  }
  if (active_.empty() || submaps_[active_.back()].nodes >= options_.nodes_per_submap) {
    Submap s;
    s.local = {local.x, local.y, 0.0};
    s.global = ToGlobal(s.local);
    MapperOptions grid = options_.submap;
    grid.center_x_m = local.x;
    grid.center_y_m = local.y;
    s.grid = std::make_unique<LogOddsMapper>(grid);
    submaps_.push_back(std::move(s));
    active_.push_back(static_cast<int>(submaps_.size()) - 1);
    ++stats_.submaps;
  }
  for (int si : active_) {
    Submap& s = submaps_[si];
    s.grid->Insert(*n.rays, local);
    s.dirty = true;
    ++s.nodes;
    if (s.first_node < 0) s.first_node = index;
    s.last_node = index;
    n.submaps.push_back(si);
    constraints_.push_back({PoseConstraint::kIntraSubmap, si, index, s.local.Inverse().Compose(local),
                            options_.local_translation_weight, options_.local_rotation_weight, 0.0});
  }
  if (index > 0) {
    constraints_.push_back({PoseConstraint::kConsecutive, index - 1, index,
                            nodes_[index - 1].local.Inverse().Compose(local), options_.consecutive_translation_weight,
                            options_.consecutive_rotation_weight, 0.0});
    // After a recovery the odometry between the two nodes is what was implausible: left out.
    if ((options_.odometry_translation_weight > 0 || options_.odometry_rotation_weight > 0) && !odometry_doubtful_) {
      constraints_.push_back({PoseConstraint::kOdometry, index - 1, index,
                              nodes_[index - 1].odometry.Inverse().Compose(odometry),
                              options_.odometry_translation_weight, options_.odometry_rotation_weight, 0.0});
    }
  }
  nodes_.push_back(std::move(n));
  odometry_doubtful_ = false;
  ++nodes_since_solve_;
  ++stats_.nodes;
  if (submaps_[active_.front()].nodes >= 2 * options_.nodes_per_submap) {
    const int finished = active_.front();
    active_.erase(active_.begin());
    FinishSubmap(finished);
  }
  if (index % options_.loop_every_nodes == 0) {
    for (size_t si = 0; si < submaps_.size(); ++si) {
      if (submaps_[si].finished) QueueSearches(index, static_cast<int>(si));
    }
  }
}

void GraphSlam::FinishSubmap(int index) {
  Submap& s = submaps_[index];
  // Cropped to what the submap saw: a finished submap keeps its levels for every later search.
  s.loop = std::make_shared<const LoopField>(
      CropToKnown(s.grid->map(), 0.5), options_.field_sigma_m, options_.occupied_threshold,
      std::min(options_.loop_levels, LevelsFor(options_.loop_window.linear_m, options_.submap.resolution_m)));
  s.grid.reset();
  s.field.reset();
  s.wide.reset();
  s.finished = true;
  s.dirty = false;
  // The nodes before it may see it too (the robot came back to where it is now).
  for (size_t node = 0; node < nodes_.size(); node += options_.loop_every_nodes) {
    QueueSearches(static_cast<int>(node), index);
  }
}

void GraphSlam::QueueSearches(int node, int submap) {
  const Node& n = nodes_[node];
  const auto holds = [&](int s) { return std::find(n.submaps.begin(), n.submaps.end(), s) != n.submaps.end(); };
  if (holds(submap)) return;
  const Submap& s = submaps_[submap];
  if (std::hypot(n.global.x - s.global.x, n.global.y - s.global.y) > options_.loop_max_distance_m) return;
  const SearchWindow w = LoopWindow(n, s);
  if (w.linear_m < options_.loop_window.linear_m || w.angular_rad < options_.loop_window.angular_rad) {
    ++stats_.loop_searches_bounded;
  }
  // The neighbour that verifies a closure: finished, sharing nodes with the submap, not holding the node.
  int verify = -1;
  if (options_.loop_verify_tolerance_m > 0) {
    for (int v : {submap + 1, submap - 1}) {
      if (v < 0 || v >= static_cast<int>(submaps_.size()) || !submaps_[v].finished || holds(v)) continue;
      verify = v;
      break;
    }
  }
  pending_.push_back({node, submap, w, verify});
}

ClosureCheck VerifyClosure(const MatchGrid& neighbour, const std::vector<Point2>& points,
                           const std::vector<Point2>& loop_points, const Pose2D& implied, const GraphSlamOptions& o) {
  const MatchResult v = MatchBranchAndBound(neighbour, loop_points, implied, o.loop_verify_window, o.loop_min_score);
  if (!v.found) return ClosureCheck::kUnverifiable;
  // Off the search's lattice of cells, as the closure itself was.
  const Pose2D found = RefineMatch(neighbour, points, v.pose, o.refine);
  // Along a corridor neither submap can tell where the node is: only the disagreement across it counts.
  double dx = found.x - implied.x, dy = found.y - implied.y, ax, ay;
  if (AlongCorridor(points, implied.theta, o.front_min_constraint_ratio, dx, dy, &ax, &ay)) dx -= ax, dy -= ay;
  return std::hypot(dx, dy) > o.loop_verify_tolerance_m ? ClosureCheck::kContradicted : ClosureCheck::kConfirmed;
}

SearchWindow LoopSearchWindow(const GraphSlamOptions& o, double path_m, bool doubtful) {
  SearchWindow w = o.loop_window;
  if (doubtful) return w;
  if (o.loop_drift_m_per_m > 0) {
    w.linear_m = std::min(w.linear_m, o.local_window.linear_m + o.loop_drift_m_per_m * path_m);
  }
  if (o.loop_drift_rad_per_m > 0) {
    w.angular_rad = std::min(w.angular_rad, o.local_window.angular_rad + o.loop_drift_rad_per_m * path_m);
  }
  return w;
}

SearchWindow RecoverySearchWindow(const GraphSlamOptions& o, double unmatched_m, bool doubtful,
                                  double doubtful_reach_m) {
  SearchWindow w = o.recover_window;
  if (o.recover_slack_m <= 0 || (doubtful && !(doubtful_reach_m >= 0))) return w;
  const double reach = doubtful ? std::max(unmatched_m, doubtful_reach_m) : unmatched_m;
  w.linear_m = std::min(w.linear_m, std::max(o.local_window.linear_m, reach + o.recover_slack_m));
  return w;
}

OdometryDoubt Merge(const OdometryDoubt& a, const OdometryDoubt& b) {
  if (!a.doubtful) return b;
  if (!b.doubtful) return a;
  // A restart anywhere leaves any motion possible.
  return {true, a.unobserved_s < 0 || b.unobserved_s < 0 ? -1.0 : std::max(a.unobserved_s, b.unobserved_s)};
}

void TopSpeed::Add(double t_s, const Pose2D& pose, bool trusted) {
  constexpr double kMinSpan = 1.0, kMaxSpan = 2.0;
  if (!trusted || !std::isfinite(t_s) || (!recent_.empty() && t_s <= recent_.back().first)) recent_.clear();
  // Keep the newest pose at least kMinSpan old, and those after it.
  while (recent_.size() >= 2 && t_s - recent_[1].first >= kMinSpan) recent_.pop_front();
  if (!recent_.empty()) {
    const double span = t_s - recent_.front().first;
    if (span >= kMinSpan && span <= kMaxSpan) {
      const double v = std::hypot(pose.x - recent_.front().second.x, pose.y - recent_.front().second.y) / span;
      ++histogram_[static_cast<int>(std::clamp(v / kBin, 0.0, kBins - 1.0))];
      ++spans_;
    }
  }
  if (std::isfinite(t_s)) recent_.emplace_back(t_s, pose);
}

double TopSpeed::Value() const {
  constexpr int kMinSpans = 100;  // below, the 99th percentile would be the maximum
  if (spans_ < kMinSpans) return -1.0;
  // The 99th percentile, at its bin's upper edge.
  const int need = spans_ - spans_ / 100;
  int seen = 0;
  for (int b = 0; b < kBins; ++b) {
    seen += histogram_[b];
    if (seen >= need) return (b + 1) * kBin;
  }
  return kBins * kBin;
}

SearchWindow GraphSlam::LoopWindow(const Node& n, const Submap& s) const {
  // The path between the node and the nearer end of the submap's nodes, and whether the front end
  // recovered or doubted its odometry anywhere on it.
  const Node& near = nodes_[n.path_m >= nodes_[s.last_node].path_m ? s.last_node : s.first_node];
  return LoopSearchWindow(options_, std::abs(n.path_m - near.path_m), n.doubtful != near.doubtful);
}

std::unique_ptr<GraphSlam::Job> GraphSlam::MakeJob(int iterations, bool render) {
  auto job = std::make_unique<Job>();
  job->searches = std::move(pending_);
  pending_.clear();
  for (const Search& q : job->searches) {
    job->search_points.push_back(nodes_[q.node].points);
    job->search_loop_points.push_back(nodes_[q.node].loop_points);
    job->search_fields.push_back(submaps_[q.submap].loop);
    job->search_submap_local.push_back(submaps_[q.submap].local);
    job->verify_fields.push_back(q.verify >= 0 ? submaps_[q.verify].loop : nullptr);
    job->verify_submap_local.push_back(q.verify >= 0 ? submaps_[q.verify].local : Pose2D{});
  }
  for (const Node& n : nodes_) job->nodes.push_back(n.global);
  for (const Submap& s : submaps_) job->submaps.push_back(s.global);
  job->constraints = constraints_;
  if (render) {
    job->scans = scans_;
  }
  job->iterations = iterations;
  nodes_since_solve_ = 0;
  return job;
}

void GraphSlam::RunJob(Job* job) const {
  auto t0 = Clock::now();
  for (size_t i = 0; i < job->searches.size(); ++i) {
    const Search& q = job->searches[i];
    const Pose2D& origin = job->search_submap_local[i];
    // The node's pose in the submap's grid, by the current estimate.
    const Pose2D guess = origin.Compose(job->submaps[q.submap].Inverse().Compose(job->nodes[q.node]));
    const MatchGrid& field = job->search_fields[i]->Get();
    const MatchResult m =
        MatchBranchAndBound(field, *job->search_loop_points[i], guess, q.window, options_.loop_min_score);
    ++job->searched;
    if (!m.found) continue;
    const Pose2D refined = RefineMatch(field, *job->search_points[i], m.pose, options_.refine);
    if (q.verify >= 0) {
      // Where the closure puts the node, in the neighbour's grid; the neighbour must find it there.
      const Pose2D global = job->submaps[q.submap].Compose(origin.Inverse().Compose(refined));
      const Pose2D& v_origin = job->verify_submap_local[i];
      const Pose2D implied = v_origin.Compose(job->submaps[q.verify].Inverse().Compose(global));
      const ClosureCheck check = VerifyClosure(job->verify_fields[i]->Get(), *job->search_points[i],
                                               *job->search_loop_points[i], implied, options_);
      if (check == ClosureCheck::kUnverifiable) ++job->unverified;
      if (check == ClosureCheck::kContradicted) {
        ++job->contradicted;
        continue;
      }
    }
    job->found.push_back({PoseConstraint::kLoopClosure, q.submap, q.node, origin.Inverse().Compose(refined),
                          options_.loop_translation_weight, options_.loop_rotation_weight, m.score});
  }
  job->search_s = Since(t0);
  job->constraints.insert(job->constraints.end(), job->found.begin(), job->found.end());
  PoseGraphOptions graph = options_.graph;
  graph.max_iterations = job->iterations;
  job->summary = OptimizePoseGraph(&job->nodes, &job->submaps, job->constraints, graph);
  for (int idx : job->summary.rejected) {
    const PoseConstraint& c = job->constraints[idx];
    job->rejected.push_back({c.to, c.from, c.score, ConstraintResidual(c, job->nodes, job->submaps)});
  }
  if (!job->scans.empty()) {
    t0 = Clock::now();
    job->map.emplace(map_options_);
    InsertScans(job->scans, 0, job->nodes, &*job->map);
    job->render_s = Since(t0);
  }
}

void GraphSlam::ApplyJob(Job* job) {
  const auto t0 = Clock::now();
  const size_t n_old = job->nodes.size(), s_old = job->submaps.size();
  if (n_old > 0) {
    for (size_t i = 0; i < n_old; ++i) nodes_[i].global = job->nodes[i];
    for (size_t i = 0; i < s_old; ++i) submaps_[i].global = job->submaps[i];
    correction_ = job->nodes.back().Compose(nodes_[n_old - 1].local.Inverse());
    for (size_t i = n_old; i < nodes_.size(); ++i) nodes_[i].global = ToGlobal(nodes_[i].local);
    for (size_t i = s_old; i < submaps_.size(); ++i) submaps_[i].global = ToGlobal(submaps_[i].local);
  }
  stats_.rejected = std::move(job->rejected);
  constraints_.insert(constraints_.end(), job->found.begin(), job->found.end());
  stats_.loop_searches += job->searched;
  stats_.loop_closures += static_cast<int64_t>(job->found.size());
  stats_.loop_closures_contradicted += job->contradicted;
  stats_.loop_closures_unverified += job->unverified;
  ++stats_.optimizations;
  stats_.optimize_s += job->summary.seconds;
  stats_.loop_search_s += job->search_s;
  if (job->map) {
    map_ = std::move(*job->map);
    InsertScans(scans_, job->scans.size(), NodePoses(), &map_);
    stats_.render_s += job->render_s;
  }
  stats_.apply_max_s = std::max(stats_.apply_max_s, Since(t0));
}

void GraphSlam::MaybeApplyFinished() {
  std::unique_ptr<Job> done;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    done = std::move(done_);
  }
  if (done) ApplyJob(done.get());
}

void GraphSlam::WorkerLoop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    cv_.wait(lock, [&] { return stop_ || job_; });
    if (stop_) return;
    std::unique_ptr<Job> job = std::move(job_);
    lock.unlock();
    RunJob(job.get());
    lock.lock();
    done_ = std::move(job);
    busy_ = false;
    cv_.notify_all();
  }
}

void GraphSlam::Finish() {
  if (!initialized_ || nodes_.empty()) return;
  if (options_.background) {
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait(lock, [&] { return !busy_; });
  }
  MaybeApplyFinished();
  const std::vector<int> active = active_;
  active_.clear();
  for (int si : active) FinishSubmap(si);
  std::unique_ptr<Job> job = MakeJob(options_.final_iterations, false);
  RunJob(job.get());
  ApplyJob(job.get());
  const auto t0 = Clock::now();
  map_ = LogOddsMapper(map_options_);
  InsertScans(scans_, 0, NodePoses(), &map_);
  stats_.render_s += Since(t0);
}

void GraphSlam::InsertScans(const std::vector<ScanAnchor>& scans, size_t from, const std::vector<Pose2D>& nodes,
                            LogOddsMapper* map) {
  for (size_t i = from; i < scans.size(); ++i)
    map->Insert(*scans[i].rays, nodes[scans[i].node].Compose(scans[i].relative));
}

OccupancyGrid GraphSlam::RenderMap(double resolution_m) const {
  if (!(resolution_m > 0)) throw std::invalid_argument("graph SLAM: the map's resolution must be positive");
  MapperOptions o = map_options_;
  o.resolution_m = resolution_m;
  LogOddsMapper map(o);
  InsertScans(scans_, 0, NodePoses(), &map);
  return map.map();
}

G2oGraph GraphSlam::Graph() const {
  std::vector<Pose2D> submaps;
  for (const Submap& s : submaps_) submaps.push_back(s.global);
  return ToG2o(NodePoses(), submaps, constraints_);
}

std::vector<Pose2D> GraphSlam::NodePoses() const {
  std::vector<Pose2D> out;
  out.reserve(nodes_.size());
  for (const Node& n : nodes_) out.push_back(n.global);
  return out;
}

std::vector<Pose2D> GraphSlam::Trajectory() const {
  std::vector<Pose2D> out;
  out.reserve(scans_.size());
  for (const ScanAnchor& a : scans_) out.push_back(nodes_[a.node].global.Compose(a.relative));
  return out;
}

}  // namespace mbot::mapping
