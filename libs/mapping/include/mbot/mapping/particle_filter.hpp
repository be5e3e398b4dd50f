// Monte-Carlo localization: low-variance resampling after motion, the odometry action model, a
// scan likelihood in log space, and a pose estimate from the best particles. Global localization
// spreads particles over the map's free space; augmented MCL (Thrun et al. §8.3.5) injects random
// particles when the short-term scan fit drops below the long-term one, and a filter whose scans
// stop fitting the map says it is lost and, if allowed, relocalizes globally.
// Particles are moved and weighed on several threads; every random draw comes from a stream keyed
// by (seed, update, particle), so results are identical for any thread count.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "mbot/mapping/action_model.hpp"
#include "mbot/mapping/occupancy_grid.hpp"
#include "mbot/mapping/sensor_model.hpp"
#include "mbot/motion/pose2d.hpp"

namespace mbot::mapping {

struct Particle {
  motion::Pose2D pose;
  double weight = 0.0;  // normalised
};

struct SearchBox {
  double min_x = 0, max_x = 0, min_y = 0, max_y = 0;
};

struct ParticleFilterOptions {
  int particles = 1000;
  double top_fraction = 0.15;  // the estimate is the weighted mean of this share of the best particles
  int threads = 0;             // 0: all cores
  // Global localization (and relocalization when lost).
  int global_particles = 20000;
  // When set, the initial global search draws only from the free cells inside this box (what the
  // operator knows about the start); relocalization after getting lost always uses all free space.
  std::optional<SearchBox> global_region;
  double converged_spread_m = 0.15;  // a global search has converged when the particles' spread is below this
  // While searching globally the scan likelihood is tempered so the effective sample size stays at
  // least this share of the particles (0: never temper).
  double global_min_ess_fraction = 0.05;
  // A settled global search is accepted only when this share of the scan fits the map at the
  // estimate; otherwise the particles are spread again.
  double converged_inlier_fraction = 0.75;
  // Augmented MCL.
  bool augmented = false;
  double alpha_slow = 0.02;
  double alpha_fast = 0.3;
  double max_injection = 0.05;  // at most this share of the particles is replaced per update
  // Lost: the estimate's inlier share stays below lost_inlier_fraction, or the short-term scan fit
  // below lost_fit_ratio times the long-term one, for `lost_scans` updates in a row.
  double lost_inlier_fraction = 0.4;
  double lost_fit_ratio = 0.7;
  int lost_scans = 3;
  bool relocalize_when_lost = false;
};

struct FilterStatus {
  motion::Pose2D pose;
  double ess = 0.0;  // effective sample size after weighing
  int particles = 0;
  int injected = 0;            // random particles injected by augmented MCL this update
  double inlier_fraction = 0;  // of the scan at the estimate
  double fit_ratio = 1;        // short-term over long-term scan-fit average (augmented MCL's signal)
  double spread_m = 0;         // weighted standard deviation of the particle positions
  bool lost = false;
  bool relocalized = false;  // the filter was re-spread over the free space after this update
  bool converged = true;     // false while a global search has not settled
  double tempering = 1.0;    // exponent applied to the scan likelihood this update (< 1 while searching)
};

class ParticleFilter {
 public:
  ParticleFilter(const ParticleFilterOptions& options, uint64_t seed);

  // All particles at `pose`, or drawn around it when sigmas are > 0.
  void InitializeAt(const motion::Pose2D& pose, double sigma_xy_m = 0.0, double sigma_theta_rad = 0.0);
  // Where random particles may go: the map's free cells (log-odds < 0). Needed for global
  // localization and augmented MCL.
  void SetFreeSpace(const OccupancyGrid& map);
  // global_particles particles uniform over the free space (inside global_region when set),
  // uniform heading.
  void InitializeGlobal();

  // One filter step after the robot moved by `step`: resample, move, weigh, estimate.
  FilterStatus Update(const ActionModel& action, const OdometryStep& step, const SensorModel& sensor,
                      const ScanPoints& scan);

  const std::vector<Particle>& particles() const { return particles_; }
  const FilterStatus& status() const { return status_; }
  // Moves every particle and the estimate by `correction` (map frame: p ← correction ∘ p).
  void Shift(const motion::Pose2D& correction);
  int64_t updates() const { return updates_; }

 private:
  void Spread(const std::vector<int32_t>& cells);
  motion::Pose2D RandomFreePose(const std::vector<int32_t>& cells, uint64_t key) const;
  void Resample(int count);
  void Estimate();

  ParticleFilterOptions options_;
  uint64_t seed_;
  int64_t updates_ = 0;
  std::vector<Particle> particles_;
  std::vector<Particle> scratch_;
  std::vector<double> log_w_;
  std::vector<uint32_t> order_;  // Estimate's scratch
  FilterStatus status_;
  bool global_ = false;
  double w_slow_ = 0.0, w_fast_ = 0.0;
  int bad_scans_ = 0;
  // Free space for random particles.
  std::vector<int32_t> free_cells_;
  std::vector<int32_t> region_cells_;  // free cells inside global_region
  int free_width_ = 0;
  double free_resolution_ = 0.05, free_origin_x_ = 0, free_origin_y_ = 0;
};

}  // namespace mbot::mapping
