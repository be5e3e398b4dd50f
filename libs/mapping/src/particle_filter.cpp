#include "mbot/mapping/particle_filter.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "mbot/mapping/random.hpp"

namespace mbot::mapping {
namespace {
// Stream tags, so the draws of different purposes never share a key.
constexpr uint64_t kTagInit = 1, kTagResample = 2, kTagInject = 3, kTagMove = 4, kTagGlobal = 5;
}  // namespace

ParticleFilter::ParticleFilter(const ParticleFilterOptions& options, uint64_t seed) : options_(options), seed_(seed) {
  if (options.particles < 1) throw std::invalid_argument("particle filter: particles must be >= 1");
}

void ParticleFilter::InitializeAt(const motion::Pose2D& pose, double sigma_xy_m, double sigma_theta_rad) {
  particles_.assign(options_.particles, Particle{pose, 1.0 / options_.particles});
  for (int i = 0; i < options_.particles; ++i) {
    CounterRng rng(StreamKey(seed_, kTagInit, i));
    motion::Pose2D& p = particles_[i].pose;
    p.x += sigma_xy_m * rng.Normal();
    p.y += sigma_xy_m * rng.Normal();
    p.theta = motion::WrapAngle(p.theta + sigma_theta_rad * rng.Normal());
  }
  global_ = false;
  bad_scans_ = 0;
  w_slow_ = w_fast_ = 0.0;
  status_ = FilterStatus{};
  status_.pose = pose;
  status_.particles = options_.particles;
}

void ParticleFilter::SetFreeSpace(const OccupancyGrid& map) {
  free_cells_.clear();
  for (int y = 0; y < map.height(); ++y) {
    for (int x = 0; x < map.width(); ++x) {
      if (map.at(x, y) < 0) free_cells_.push_back(y * map.width() + x);
    }
  }
  free_width_ = map.width();
  free_resolution_ = map.resolution();
  free_origin_x_ = map.origin_x();
  free_origin_y_ = map.origin_y();
  region_cells_.clear();
  if (const auto& box = options_.global_region) {
    for (int32_t cell : free_cells_) {
      double x, y;
      map.CellToWorld(cell % free_width_, cell / free_width_, &x, &y);
      if (x >= box->min_x && x <= box->max_x && y >= box->min_y && y <= box->max_y) region_cells_.push_back(cell);
    }
  }
}

motion::Pose2D ParticleFilter::RandomFreePose(const std::vector<int32_t>& cells, uint64_t key) const {
  CounterRng rng(key);
  const size_t k = std::min(cells.size() - 1, static_cast<size_t>(rng.Uniform() * cells.size()));
  const int cell = cells[k];
  const int cx = cell % free_width_, cy = cell / free_width_;
  return {free_origin_x_ + (cx + rng.Uniform()) * free_resolution_,
          free_origin_y_ + (cy + rng.Uniform()) * free_resolution_,
          motion::WrapAngle((2.0 * rng.Uniform() - 1.0) * M_PI)};
}

void ParticleFilter::InitializeGlobal() {
  if (free_cells_.empty()) throw std::runtime_error("global localization: the map has no free cells");
  if (options_.global_region) {
    if (region_cells_.empty()) throw std::runtime_error("global localization: no free cells inside global_region");
    Spread(region_cells_);
  } else {
    Spread(free_cells_);
  }
}

void ParticleFilter::Spread(const std::vector<int32_t>& cells) {
  const int n = std::max(options_.global_particles, options_.particles);
  particles_.resize(n);
  const uint64_t base = StreamKey(seed_, kTagGlobal, static_cast<uint64_t>(updates_));
  for (int i = 0; i < n; ++i) particles_[i] = Particle{RandomFreePose(cells, StreamKey(base, 0, i)), 1.0 / n};
  global_ = true;
  bad_scans_ = 0;
  w_slow_ = w_fast_ = 0.0;
  status_.converged = false;
  status_.particles = n;
}

void ParticleFilter::Resample(int count) {
  // Low-variance (systematic) resampling: one random offset, `count` evenly spaced pointers.
  scratch_.resize(count);
  CounterRng rng(StreamKey(seed_, kTagResample, static_cast<uint64_t>(updates_)));
  const double step = 1.0 / count;
  double u = rng.Uniform() * step;
  double c = particles_[0].weight;
  size_t i = 0;
  for (int m = 0; m < count; ++m) {
    while (u > c && i + 1 < particles_.size()) c += particles_[++i].weight;
    scratch_[m] = Particle{particles_[i].pose, step};
    u += step;
  }
  particles_.swap(scratch_);
}

FilterStatus ParticleFilter::Update(const ActionModel& action, const OdometryStep& step, const SensorModel& sensor,
                                    const ScanPoints& scan) {
  if (particles_.empty()) throw std::logic_error("particle filter: update before initialization");
  ++updates_;
  const int count = global_ ? std::max(options_.global_particles, options_.particles) : options_.particles;
  Resample(count);

  // Augmented MCL: replace a share of the particles with random free-space poses.
  int injected = 0;
  if (options_.augmented && !free_cells_.empty() && !global_ && w_slow_ > 0.0) {
    const double p = std::min(options_.max_injection, std::max(0.0, 1.0 - w_fast_ / w_slow_));
    injected = static_cast<int>(p * count);
    const uint64_t base = StreamKey(seed_, kTagInject, static_cast<uint64_t>(updates_));
    for (int k = 0; k < injected; ++k) {
      // Spread the replaced slots over the set so no one region of the resampled set is favoured.
      const size_t slot = static_cast<size_t>((k + 0.5) * count / injected);
      particles_[std::min(slot, particles_.size() - 1)].pose = RandomFreePose(free_cells_, StreamKey(base, 0, k));
    }
  }

  const int n = static_cast<int>(particles_.size());
  log_w_.resize(n);
  const uint64_t move_base = StreamKey(seed_, kTagMove, static_cast<uint64_t>(updates_));
  const int threads = options_.threads > 0 ? options_.threads : omp_get_max_threads();
  const ActionModel::StepNoise noise = action.NoiseOf(step);
#pragma omp parallel for schedule(static) num_threads(threads) if (n >= 256)
  for (int i = 0; i < n; ++i) {
    particles_[i].pose = action.Sample(particles_[i].pose, step, noise, StreamKey(move_base, 0, i));
    log_w_[i] = sensor.LogLikelihood(particles_[i].pose, scan);
  }

  // Normalise in log space; the scan fit (per-beam geometric-mean likelihood) drives augmented MCL.
  const double max_log = *std::max_element(log_w_.begin(), log_w_.end());
  double sum = 0.0, fit = 0.0;
  const double per_beam = scan.size() > 0 ? 1.0 / (scan.size() * std::max(1e-12, sensor.options().log_scale)) : 0.0;
  for (int i = 0; i < n; ++i) fit += std::exp(log_w_[i] * per_beam);
  fit /= n;
  // During a global search one scan's likelihood is so peaked that a single resampling would keep
  // only the best particle drawn, right or aliased. Temper it (weights ∝ L^β, β ≤ 1) so at least
  // global_min_ess_fraction of the particles stay effective: evidence then accumulates over scans.
  double beta = 1.0;
  if (global_ && options_.global_min_ess_fraction > 0.0) {
    const double target = options_.global_min_ess_fraction * n;
    auto ess_at = [&](double b) {
      double s1 = 0.0, s2 = 0.0;
      for (int i = 0; i < n; ++i) {
        const double w = std::exp(b * (log_w_[i] - max_log));
        s1 += w;
        s2 += w * w;
      }
      return s1 * s1 / s2;
    };
    if (ess_at(1.0) < target) {
      double lo = 0.0, hi = 1.0;  // ESS falls as β grows: keep the largest β that meets the target
      for (int it = 0; it < 30; ++it) {
        const double mid = 0.5 * (lo + hi);
        (ess_at(mid) >= target ? lo : hi) = mid;
      }
      beta = lo;
    }
  }
  status_.tempering = beta;
  for (int i = 0; i < n; ++i) {
    particles_[i].weight = std::exp(beta * (log_w_[i] - max_log));
    sum += particles_[i].weight;
  }
  double sum_sq = 0.0;
  for (Particle& p : particles_) {
    p.weight /= sum;
    sum_sq += p.weight * p.weight;
  }
  if (w_slow_ == 0.0) {
    w_slow_ = w_fast_ = fit;
  } else {
    w_slow_ += options_.alpha_slow * (fit - w_slow_);
    w_fast_ += options_.alpha_fast * (fit - w_fast_);
  }

  Estimate();
  status_.ess = 1.0 / sum_sq;
  status_.particles = n;
  status_.injected = injected;
  status_.inlier_fraction = sensor.has_map() ? sensor.InlierFraction(status_.pose, scan) : 1.0;
  status_.relocalized = false;
  bool respread = false;
  if (global_ && status_.spread_m < options_.converged_spread_m) {
    // Settled; but on a place that does not explain the scan (an aliased corridor, the right pose
    // never drawn) the search starts again with fresh particles instead of tracking the wrong place.
    if (status_.inlier_fraction >= options_.converged_inlier_fraction) {
      global_ = false;
      w_slow_ = w_fast_ = fit;  // the averages so far scored random particles: restart them
    } else {
      respread = true;
    }
  }
  status_.converged = !global_;

  status_.fit_ratio = w_slow_ > 0 ? w_fast_ / w_slow_ : 1.0;
  const bool bad =
      status_.inlier_fraction < options_.lost_inlier_fraction || status_.fit_ratio < options_.lost_fit_ratio;
  bad_scans_ = bad ? bad_scans_ + 1 : 0;
  status_.lost = bad_scans_ >= options_.lost_scans;
  if ((respread || (status_.lost && options_.relocalize_when_lost && !global_)) && !free_cells_.empty()) {
    Spread(respread && options_.global_region ? region_cells_ : free_cells_);
    status_.relocalized = true;
  }
  return status_;
}

void ParticleFilter::Shift(const motion::Pose2D& correction) {
  for (Particle& p : particles_) p.pose = correction.Compose(p.pose);
  status_.pose = correction.Compose(status_.pose);
}

void ParticleFilter::Estimate() {
  const size_t n = particles_.size();
  const size_t k = std::max<size_t>(1, static_cast<size_t>(std::ceil(options_.top_fraction * n)));
  std::vector<uint32_t>& order = order_;  // kept between updates: no allocation per scan
  order.resize(n);
  std::iota(order.begin(), order.end(), 0u);
  std::nth_element(order.begin(), order.begin() + (k - 1), order.end(), [&](uint32_t a, uint32_t b) {
    return particles_[a].weight > particles_[b].weight || (particles_[a].weight == particles_[b].weight && a < b);
  });
  double w = 0, x = 0, y = 0, cs = 0, sn = 0;
  for (size_t j = 0; j < k; ++j) {
    const Particle& p = particles_[order[j]];
    w += p.weight;
    x += p.weight * p.pose.x;
    y += p.weight * p.pose.y;
    cs += p.weight * std::cos(p.pose.theta);
    sn += p.weight * std::sin(p.pose.theta);
  }
  if (w <= 0) w = 1;
  status_.pose = {x / w, y / w, std::atan2(sn, cs)};
  // Spread of the whole set around its weighted mean.
  double mx = 0, my = 0;
  for (const Particle& p : particles_) {
    mx += p.weight * p.pose.x;
    my += p.weight * p.pose.y;
  }
  double var = 0;
  for (const Particle& p : particles_)
    var += p.weight * ((p.pose.x - mx) * (p.pose.x - mx) + (p.pose.y - my) * (p.pose.y - my));
  status_.spread_m = std::sqrt(var);
}

}  // namespace mbot::mapping
