// One SLAM system for all four modes the stack runs:
//   mapping-only  poses come from outside (motion capture, a reference channel); scans build the map;
//   action-only   particles follow odometry through the action model alone; scans build the map;
//   localization  particles weighed against a known map, which is not changed;
//   full SLAM     localization against the map built so far, then the scan is added at the estimate;
//   graph SLAM    scan-to-submap matching and a pose graph that closes loops (graph_slam.hpp), no particles.
// Between filter updates (the robot has not moved enough) the pose follows odometry.
#pragma once

#include <cmath>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "mbot/mapping/action_model.hpp"
#include "mbot/mapping/graph_slam.hpp"
#include "mbot/mapping/log_odds_mapper.hpp"
#include "mbot/mapping/moving_scan.hpp"
#include "mbot/mapping/particle_filter.hpp"
#include "mbot/mapping/ndt.hpp"
#include "mbot/mapping/sensor_model.hpp"
#include "mbot/msgs/status.hpp"

namespace mbot::mapping {

using msgs::SlamMode;
using msgs::SlamState;
using msgs::SlamStatus;
using msgs::ToString;
SlamState StateOf(SlamMode mode, const FilterStatus& status);

struct SlamOptions {
  SlamMode mode = SlamMode::kFullSlam;
  MapperOptions mapper;
  ActionModelOptions action;
  SensorModelOptions sensor;
  ParticleFilterOptions filter;
  GraphSlamOptions graph;  // graph SLAM only
  // Full SLAM: a scan whose returns fit the map at its pose at under this share of the recent
  // mapped scans' median fit (a corrupt or misplaced scan: a bad stamp, a bad odometry step) is not
  // mapped; 0: off. After gate_max_scans such scans in a row the next is mapped whatever it fits
  // (the world changed, or the pose was wrong and was corrected: the map must follow). Not while
  // localization is switched off (the fit is then taken against a map that may be far behind).
  double gate_fit_ratio = 0.5;
  int gate_max_scans = 3;
  // Full SLAM: after each filter update the estimate is fitted to the hits the map holds (the
  // normal-distributions transform of ndt.hpp, held near the filter's answer by `refine`'s priors),
  // and every particle moves by the same correction. The filter weighs whole cells; the fit places
  // the scan between them. Not while the filter is lost or re-spread; a fit is taken only where at
  // least a quarter of the scan's points lie on the map's hits and it moves the estimate by at most three
  // of the priors' deviations. refine.occupied_threshold is the sensor model's.
  bool refine_estimate = false;
  NdtOptions refine;
};

struct SlamStep {
  motion::Pose2D pose;
  bool filter_updated = false;  // the particle filter ran on this scan
  FilterStatus status;          // the filter's state after this scan (when it has one)
  bool gated = false;           // full SLAM: the scan's fit to the map collapsed, so it was not mapped
};

// What happened to the filter over a run, scan by scan: when global localization converged, when
// the filter flagged the robot lost (a kidnapping) and when it recovered (converged again with
// the scan explaining at least `recovered_inlier_fraction` of its returns).
class SlamEventTracker {
 public:
  struct Lost {
    double at_s = 0;
    int at_scan = 0;
    double recovered_at_s = -1;  // -1: not (yet)
    int recovered_at_scan = -1;
  };
  explicit SlamEventTracker(double recovered_inlier_fraction) : recovered_inlier_fraction_(recovered_inlier_fraction) {}
  // Global localization started (its convergence is then tracked).
  void GlobalStarted() { global_ = true; }
  // One processed scan (0-based index) at `t_s` since the start; `updated`: the filter ran on it.
  // Returns a line worth logging when something happened, else "".
  std::string Add(double t_s, int scan, bool updated, const FilterStatus& status);

  bool global() const { return global_; }
  double converged_at_s() const { return converged_at_s_; }  // -1: not converged
  int converged_at_scan() const { return converged_scan_; }
  const std::vector<Lost>& lost() const { return lost_; }

 private:
  double recovered_inlier_fraction_;
  bool global_ = false;
  double converged_at_s_ = -1;
  int converged_scan_ = -1;
  std::vector<Lost> lost_;
};

class Slam {
 public:
  Slam(const SlamOptions& options, uint64_t seed);

  // The known map (localization; also a starting map for full SLAM).
  void SetMap(OccupancyGrid map);
  // Starts at `pose`, with `odometry` the odometry reading at that moment.
  void Initialize(const motion::Pose2D& pose, const motion::Pose2D& odometry, double sigma_xy_m = 0.0,
                  double sigma_theta_rad = 0.0);
  // Starts with particles spread over the known map's free space (localization only).
  void InitializeGlobal(const motion::Pose2D& odometry);
  bool initialized() const { return initialized_; }

  // One scan, its rays in the frame of the robot at the scan's end; `odometry` is the odometry pose
  // at that time; `reference` the externally given pose (mapping-only; ignored otherwise).
  // `doubt` (graph SLAM): whether the odometry since the last scan crossed a gap or a restart;
  // `time_s` (graph SLAM): the scan's time, for the robot's top speed.
  SlamStep ProcessScan(const std::vector<ScanRay>& rays, const motion::Pose2D& odometry,
                       const motion::Pose2D* reference = nullptr, const OdometryDoubt& doubt = {},
                       double time_s = std::nan(""));

  // Graph SLAM: closes the last loops and solves the graph (a no-op in the other modes).
  void Finish();
  // Graph SLAM: every scan's pose from the optimised graph, one per ProcessScan call; empty otherwise.
  std::vector<motion::Pose2D> Trajectory() const;
  const GraphSlam* graph() const { return graph_.get(); }
  // The mode's answers, so a caller need not ask for the mode: particles to show (the filter runs:
  // not mapping-only, not graph SLAM); a map that grows (not localization).
  bool HasParticles() const { return UsesFilter() && !graph_; }
  bool BuildsMap() const { return options_.mode != SlamMode::kLocalization; }

  // A person's say (the viewer), in the particle filter's modes: mapping off keeps the map as it is
  // (full SLAM then localizes on it); localization off lets the pose follow odometry alone (the
  // filter waits, and takes up the whole motion when switched on again); ClearMap forgets every
  // cell and keeps the pose and the map frame. Each throws std::invalid_argument saying why when
  // the mode cannot (graph SLAM maps every scan; localization keeps its known map; mapping-only
  // takes its poses from a reference).
  void SetMapping(bool on);
  void SetLocalization(bool on);
  void ClearMap();
  bool mapping_on() const { return mapping_on_; }
  bool localization_on() const { return localization_on_; }

  const OccupancyGrid& map() const { return graph_ ? graph_->map() : mapper_.map(); }
  const ParticleFilter& filter() const { return filter_; }
  const SlamOptions& options() const { return options_; }
  int64_t filter_updates() const { return filter_.updates(); }
  int64_t scans_gated() const { return scans_gated_; }
  int64_t estimates_refined() const { return refined_; }  // refine_estimate: fits taken

 private:
  bool UsesFilter() const { return options_.mode != SlamMode::kMappingOnly; }
  bool Gate(const std::vector<ScanRay>& rays, const motion::Pose2D& pose);
  // refine_estimate: the filter's estimate fitted to the map's hits, the particles moved with it.
  motion::Pose2D RefineEstimate(const std::vector<ScanRay>& rays);
  void ResetGate();  // a map cleared or switched: the recent fits say nothing of the next

  SlamOptions options_;
  LogOddsMapper mapper_;
  ActionModel action_;
  SensorModel sensor_;
  SensorModel no_map_sensor_;  // action-only: every particle weighs the same
  ParticleFilter filter_;
  std::unique_ptr<GraphSlam> graph_;
  bool initialized_ = false;
  bool sensor_stale_ = true;
  bool mapping_on_ = true, localization_on_ = true;
  motion::Pose2D last_odometry_;    // odometry at the last filter update
  motion::Pose2D last_estimate_;    // the estimate then
  std::deque<double> recent_fits_;  // the gate's history: the fits of the last scans taken
  int gated_in_row_ = 0;
  int64_t scans_gated_ = 0;
  int64_t refined_ = 0;
};

}  // namespace mbot::mapping
