// Graph SLAM for buildings (Hess et al., ICRA 2016, in outline): a front end that matches every scan
// against the current submap (branch-and-bound correlative search in a small window, refined by
// Ceres) and inserts the scans that moved far enough as nodes into two overlapping submaps of
// `nodes_per_submap` nodes; a back end that searches loop closures of nodes against finished
// submaps (branch and bound over a large window, accepted by score, refined by Ceres) and optimises
// the pose graph with Ceres every `optimize_every_nodes` nodes — on a worker thread when
// `background`, so the front end publishes each scan's pose at once. The map holds every scan: each
// is added at its pose when it comes, and the whole map is rendered again from the optimised poses
// after each solve (rerender_map) and at the end.
#pragma once

#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "mbot/mapping/log_odds_mapper.hpp"
#include "mbot/mapping/moving_scan.hpp"
#include "mbot/mapping/pose_graph.hpp"
#include "mbot/mapping/pose_graph_io.hpp"
#include "mbot/mapping/scan_matching.hpp"
#include "mbot/motion/pose2d.hpp"

namespace mbot::mapping {

// What the odometry says about itself since the last scan (graph SLAM's recovery search).
struct OdometryDoubt {
  bool doubtful = false;  // it spans a gap longer than recover_gap_s, or a zeroed restart
  // How long the robot went unobserved: the longest gap it spans [s]. Negative for a restart,
  // whose zeroed jump may hide any motion (the whole recover_window is searched then).
  double unobserved_s = -1.0;
};

// Two doubts about the odometry in one (a scan's own and one held from before it): a restart in
// either leaves any motion possible, else the longer gap counts.
OdometryDoubt Merge(const OdometryDoubt& a, const OdometryDoubt& b);

struct GraphSlamOptions {
  // Submaps: their own log-odds grids in the front end's frame.
  MapperOptions submap{5, 1, 0.05, 10.0, 10.0, 0.0, 0.0, true, 2.0};
  int nodes_per_submap = 60;          // a submap is finished after 2× this many nodes
  double field_sigma_m = 0.05;        // of the matching field
  int occupied_threshold = 0;         // submap cells above this count as obstacles
  double point_spacing_m = 0.0;       // thin the scan's points to this spacing (0: all)
  double loop_point_spacing_m = 0.1;  // ... for the loop-closure search (its Ceres fit takes them all)
  int min_points = 20;                // scans with fewer hits are not matched (counted)
  // Front end.
  bool local_search = true;  // correlative search before the Ceres fit
  SearchWindow local_window{0.1, 0.2, 0.005};
  RefineOptions refine;
  // Recovery from an implausible odometry prior (a glitch, a gap, a zeroed jump): a scan whose best
  // fit in the local window scores below `recover_below` × the running mean score is searched again
  // over `recover_window`; a pose found there that scores above that bound and better than the
  // local one is kept, and the odometry constraint to the next node is then left out (0: never).
  double recover_below = 0.75;
  // Where the odometry itself says it is doubtful — a gap longer than this between the odometry
  // readings around a scan, or a restart the continuity check zeroed — the recovery window is
  // searched whatever the local fit scored (the same acceptance rule; 0: only on a poor fit).
  double recover_gap_s = 1.0;
  // A recovery moves the scan only where it fits better than in the local window by this share of
  // the running mean score (0: any better fit). 0.15 kept Intel with injected glass and people from a
  // 1.2 m jump (0.566 against 0.499 locally, mean 0.708), but it also refused true recoveries on the
  // real Intel bag, whose odometry has gaps and restarts (0.0176 m with 0, 0.0201 m with 0.15; 0.0177
  // m with 0 today), and on the made-harder Intel slice (0.0200 against 0.0289 m). The bounds below
  // keep those jumps out.
  double recover_margin = 0.0;
  // A glitch is part of the odometry's own step: a recovery searches no farther from the prediction
  // than that step plus this slack (the motion the step may have missed), never beyond
  // recover_window; the steps of scans too sparse to match count too. Across an odometry gap the
  // clock may allow more (recover_speed_factor). The made-harder slices' true recoveries moved the
  // scan at most 0.17 m more than the glitched step; with people walking by and glass, wrong ones
  // moved it 1.0-1.7 m on steps of under 0.1 m. Every recovery, bounded or not, keeps within the
  // window's reach as a distance, not only as the square the search covers (0: recover_window
  // always, the clock bound too is off).
  double recover_slack_m = 0.3;
  // Across an odometry gap its step says little, but the clock does: the robot cannot have gone
  // farther than this factor times its top speed (TopSpeed: the log's own, from the matched scans)
  // times the gap (or the time since the last matched scan, if longer), so the search reaches no
  // farther than that (or the odometry's step, if longer) plus recover_slack_m. A zeroed restart,
  // whose jump may have been real motion, a top speed not yet known or a clock that ran backwards
  // search the whole recover_window. A doubt holds until a scan is matched (0: always the whole
  // window on doubtful odometry).
  double recover_speed_factor = 2.0;
  // A scan that cannot pin its position down along a direction (its surfaces' weakest information
  // below this share of their strongest, ScanTranslationConstraint: a corridor) keeps odometry's
  // motion along it; the fit would put it where the submap's walls end (0: trust the fit).
  double front_min_constraint_ratio = 0.003;
  SearchWindow recover_window{1.5, 0.5, 0.005};
  // A scan becomes a node when it moved this far from the last node (or turned this much).
  double node_distance_m = 0.1;
  double node_angle_rad = 0.0175;
  // Constraint weights.
  double local_translation_weight = 1e5, local_rotation_weight = 1e5;
  double consecutive_translation_weight = 1e5, consecutive_rotation_weight = 1e5;
  double loop_translation_weight = 1.1e4, loop_rotation_weight = 1e5;
  // Consecutive nodes' relative motion by odometry (0: no odometry constraints).
  double odometry_translation_weight = 1e3, odometry_rotation_weight = 1e3;
  // Loop closure.
  SearchWindow loop_window{3.0, 0.35, 0.005};
  double loop_min_score = 0.55;
  double loop_max_distance_m = 10.0;  // node to submap origin, by the current estimate
  // The front end's drift bounds a closure's correction: a node is searched in a finished submap
  // over the local window grown by these rates times the path the front end drove between the
  // nearer end of the submap's nodes and the node (capped by loop_window). A look-alike place farther than the
  // matched path can have drifted is never searched. A path with a recovery or doubtful odometry
  // in it is unbounded (loop_window). 0: the loop window alone.
  double loop_drift_m_per_m = 0.02;
  double loop_drift_rad_per_m = 0.01;
  // A closure found in a submap is verified in a neighbouring finished submap (the one before or
  // after it, which shares nodes with it) that the node is not in: searched there over this window
  // around the pose the closure implies, the node must be found within loop_verify_tolerance_m of
  // it. Found elsewhere, the closure is dropped; not found at all (the neighbour saw too little of
  // the place), it stands. 0: no verification.
  SearchWindow loop_verify_window{0.15, 0.1, 0.005};
  double loop_verify_tolerance_m = 0.1;
  int loop_every_nodes = 5;  // search every k-th node
  int loop_levels = 8;       // branch-and-bound levels of a finished submap
  PoseGraphOptions graph{10.0, 50, 1};
  int final_iterations = 200;
  int optimize_every_nodes = 90;
  bool background = true;
  bool rerender_map = true;  // re-render the live map from the optimised poses after each solve
};

// The window a loop-closure search of a node in a finished submap covers, for `path_m` of the front
// end's path between them (`doubtful`: a recovery or doubtful odometry on it): the local window
// grown by the drift rates times the path, never beyond loop_window.
SearchWindow LoopSearchWindow(const GraphSlamOptions& options, double path_m, bool doubtful);

// The window a recovery search covers after `unmatched_m` of odometry since the last matched scan
// (`doubtful`: a gap or a zeroed restart around it): recover_window, narrowed to ± that length plus
// recover_slack_m in x and y (never below the local window); the search also keeps within that
// distance. Where the odometry is doubtful, the length is the larger of it and `doubtful_reach_m`,
// the farthest the robot can have gone by the clock (negative: unknown, the whole window).
SearchWindow RecoverySearchWindow(const GraphSlamOptions& options, double unmatched_m, bool doubtful,
                                  double doubtful_reach_m = -1.0);

// The robot's top speed as a log shows it: the 99th percentile of its speed over spans of 1-2 s
// between matched scan poses (a span with a recovery or a doubtful step in it is left out, and a
// clock that runs backwards starts the spans again). Unknown (negative) before 100 spans, below
// which the percentile would be the maximum.
class TopSpeed {
 public:
  // A matched scan at `t_s` and `pose`; `trusted`: no recovery and no doubtful odometry since the
  // previous one (else the spans start again here).
  void Add(double t_s, const motion::Pose2D& pose, bool trusted);
  double Value() const;
  int spans() const { return spans_; }

 private:
  static constexpr double kBin = 0.01;  // m/s
  static constexpr int kBins = 1000;
  std::deque<std::pair<double, motion::Pose2D>> recent_;
  std::vector<int> histogram_ = std::vector<int>(kBins, 0);
  int spans_ = 0;
};

// A closure checked in a neighbouring finished submap: the node searched there (loop_verify_window,
// loop_min_score) around `implied`, the pose the closure puts it at in that submap's grid, is found
// within loop_verify_tolerance_m of it (across the corridor only, when `points` cannot pin its
// position down along one: front_min_constraint_ratio), found elsewhere, or not found.
enum class ClosureCheck { kConfirmed, kContradicted, kUnverifiable };
ClosureCheck VerifyClosure(const MatchGrid& neighbour, const std::vector<Point2>& points,
                           const std::vector<Point2>& loop_points, const motion::Pose2D& implied,
                           const GraphSlamOptions& options);

struct RejectedClosure {
  int node = 0, submap = 0;
  double score = 0, residual = 0;
};

struct GraphSlamStats {
  int scans = 0, nodes = 0, submaps = 0, sparse_scans = 0;
  int recovery_searches = 0, recoveries = 0;  // wide searches made, and those that moved the scan
  int doubtful_searches = 0;                  // of the searches: those the odometry's gap or restart asked for
  int doubtful_bounded = 0;                   // searches across an odometry gap the clock narrowed
  double top_speed_m_s = -1;                  // TopSpeed at the end (negative: never known)
  int degenerate_scans = 0;                   // whose motion along a corridor came from odometry
  int64_t loop_searches = 0, loop_closures = 0;
  int64_t loop_searches_bounded = 0;  // of the searches: those the path's drift bound kept inside loop_window
  // Of the closures found: those a neighbouring submap placed elsewhere (dropped), and those it
  // could not place at all (kept unverified).
  int64_t loop_closures_contradicted = 0, loop_closures_unverified = 0;
  std::vector<RejectedClosure> rejected;  // by the robust loss, at the last solve
  int optimizations = 0;
  double optimize_s = 0, loop_search_s = 0, front_end_s = 0, render_s = 0;
  // The longest a solve's result took to take in on the front end's thread (it adds the scans that
  // came in meanwhile to the re-rendered map).
  double apply_max_s = 0;
};

class GraphSlam {
 public:
  explicit GraphSlam(const GraphSlamOptions& options, const MapperOptions& map_options);
  ~GraphSlam();
  GraphSlam(const GraphSlam&) = delete;
  GraphSlam& operator=(const GraphSlam&) = delete;

  void Initialize(const motion::Pose2D& pose, const motion::Pose2D& odometry);
  bool initialized() const { return initialized_; }
  // One scan (rays in the frame of the robot at the scan's end) with the odometry then; returns the
  // scan's pose by the current estimate.
  // `doubt`: whether the odometry since the last scan spans a gap or a restart (see
  // GraphSlamOptions::recover_gap_s), so its prior is searched around widely. `time_s`: the scan's
  // time, for the robot's top speed (NaN: unknown; a doubtful step then searches the whole
  // recover_window).
  motion::Pose2D ProcessScan(const std::vector<ScanRay>& rays, const motion::Pose2D& odometry,
                             const OdometryDoubt& doubt = {}, double time_s = std::nan(""));
  // Waits for the worker, closes the last loops, solves the graph to convergence, renders the map.
  void Finish();

  // Every scan's pose so far (one per ProcessScan call), from the optimised nodes.
  std::vector<motion::Pose2D> Trajectory() const;
  const OccupancyGrid& map() const { return map_.map(); }
  // The map rendered again from every scan at its optimised pose, at another resolution.
  OccupancyGrid RenderMap(double resolution_m) const;
  // The pose graph as it stands (after Finish: the final solve's), in the g2o layout of ToG2o.
  G2oGraph Graph() const;
  const GraphSlamStats& stats() const { return stats_; }
  const GraphSlamOptions& options() const { return options_; }

 private:
  struct Node {
    motion::Pose2D local, global;
    motion::Pose2D odometry;  // the odometry reading at the node's scan
    std::shared_ptr<const std::vector<ScanRay>> rays;
    std::shared_ptr<const std::vector<Point2>> points, loop_points;
    std::vector<int> submaps;  // it was inserted into
    double path_m = 0;         // the front end's path length from the first node
    int doubtful = 0;          // recoveries and doubtful odometry steps before it (a running count)
  };
  // A finished submap's search field, built on its first search (on the worker when `background`),
  // so finishing a submap costs the front end only a crop of its grid.
  class LoopField {
   public:
    LoopField(OccupancyGrid grid, double sigma_m, int occupied_threshold, int levels)
        : grid_(std::move(grid)), sigma_m_(sigma_m), threshold_(occupied_threshold), levels_(levels) {}
    const MatchGrid& Get() const;

   private:
    mutable OccupancyGrid grid_;  // released once the field is built
    double sigma_m_;
    int threshold_, levels_;
    mutable std::once_flag once_;
    mutable std::unique_ptr<const MatchGrid> field_;
  };
  struct Submap {
    motion::Pose2D local, global;            // local: a translation (the grid is axis-aligned in the local frame)
    std::unique_ptr<LogOddsMapper> grid;     // while active
    std::shared_ptr<const MatchGrid> field;  // the front end's (while active)
    std::shared_ptr<const MatchGrid> wide;   // ... with levels for a recovery search (built on demand)
    std::shared_ptr<const LoopField> loop;   // the loop-closure search's (once finished)
    bool dirty = true;
    bool finished = false;
    int nodes = 0;
    int first_node = -1, last_node = -1;
  };
  struct Search {
    int node = 0, submap = 0;
    SearchWindow window;
    int verify = -1;  // the finished neighbour submap that verifies a closure found (-1: none)
  };
  struct ScanAnchor {
    int node = 0;
    motion::Pose2D relative;  // the scan's local pose in its node's local frame
    std::shared_ptr<const std::vector<ScanRay>> rays;
  };
  // What a solve needs, copied, and what it returns.
  struct Job {
    std::vector<Search> searches;
    std::vector<std::shared_ptr<const std::vector<Point2>>> search_points, search_loop_points;
    std::vector<std::shared_ptr<const LoopField>> search_fields, verify_fields;
    std::vector<motion::Pose2D> search_submap_local, verify_submap_local;
    std::vector<motion::Pose2D> nodes, submaps;
    std::vector<PoseConstraint> constraints;  // the found loop closures are appended
    std::vector<ScanAnchor> scans;            // for the re-render (empty: none)
    int iterations = 50;
    // Out.
    std::vector<PoseConstraint> found;
    PoseGraphSummary summary;
    std::vector<RejectedClosure> rejected;
    int64_t searched = 0, contradicted = 0, unverified = 0;
    double search_s = 0, render_s = 0;
    std::optional<LogOddsMapper> map;
  };

  void AddNode(const motion::Pose2D& local, const motion::Pose2D& odometry,
               std::shared_ptr<const std::vector<ScanRay>> rays, std::shared_ptr<const std::vector<Point2>> points);
  void FinishSubmap(int index);
  void QueueSearches(int node, int submap);
  // The loop window for `node` in finished `submap` (LoopSearchWindow).
  SearchWindow LoopWindow(const Node& node, const Submap& submap) const;
  std::unique_ptr<Job> MakeJob(int iterations, bool render);
  void RunJob(Job* job) const;
  void ApplyJob(Job* job);
  void MaybeApplyFinished();
  void WorkerLoop();
  // Adds scans[from..] to `map` at their nodes' poses.
  static void InsertScans(const std::vector<ScanAnchor>& scans, size_t from, const std::vector<motion::Pose2D>& nodes,
                          LogOddsMapper* map);
  std::vector<motion::Pose2D> NodePoses() const;
  motion::Pose2D ToGlobal(const motion::Pose2D& local) const { return correction_.Compose(local); }

  GraphSlamOptions options_;
  MapperOptions map_options_;
  bool initialized_ = false;
  motion::Pose2D last_odometry_, last_local_;
  motion::Pose2D correction_;             // global ⊕ local⁻¹, from the last solve
  double mean_score_ = 0;                 // running mean of the front end's match scores
  double unmatched_m_ = 0;                // odometry path since the last scan the front end matched
  double matched_time_s_ = std::nan("");  // the time of the last scan the front end matched
  bool untrusted_since_match_ = false;    // a recovery or doubtful odometry since then
  TopSpeed top_speed_;
  OdometryDoubt unresolved_doubt_;  // held from doubtful scans since the last matched one
  int scores_ = 0;
  bool odometry_doubtful_ = false;  // a recovery since the last node
  int doubtful_seen_ = 0;           // recoveries and doubtful odometry steps so far
  std::vector<Node> nodes_;
  std::vector<Submap> submaps_;
  std::vector<int> active_;  // submap indices, oldest first
  std::vector<PoseConstraint> constraints_;
  std::vector<Search> pending_;
  int nodes_since_solve_ = 0;
  std::vector<ScanAnchor> scans_;
  LogOddsMapper map_;
  GraphSlamStats stats_;

  // The worker: one job at a time.
  std::thread worker_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::unique_ptr<Job> job_;   // handed to the worker
  std::unique_ptr<Job> done_;  // returned by it
  bool busy_ = false, stop_ = false;
};

}  // namespace mbot::mapping
