#include "mbot/mapping/slam.hpp"

#include "mbot/common/strings.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mbot::mapping {

SlamState StateOf(SlamMode mode, const FilterStatus& status) {
  if (mode != SlamMode::kLocalization) return SlamState::kMapping;
  return !status.converged ? SlamState::kLocalizing : status.lost ? SlamState::kLost : SlamState::kLocalized;
}

std::string SlamEventTracker::Add(double t, int scan, bool updated, const FilterStatus& status) {
  std::string said;
  if (global_ && converged_at_s_ < 0 && updated && status.converged) {
    converged_at_s_ = t;
    converged_scan_ = scan;
    said = "global localization converged after " + std::to_string(scan + 1) + " scans (" + Significant(t, 4) +
           " s), spread " + Significant(status.spread_m, 3) + " m";
  }
  const bool open = !lost_.empty() && lost_.back().recovered_at_scan < 0;
  if (status.lost && !open) {
    lost_.push_back({t, scan, -1, -1});
    said += (said.empty() ? "" : "; ") + std::string("lost at ") + Significant(t, 4) + " s (inlier share " +
            Significant(status.inlier_fraction, 3) + ")";
  } else if (open && updated && status.converged && !status.lost &&
             status.inlier_fraction >= recovered_inlier_fraction_) {
    lost_.back().recovered_at_s = t;
    lost_.back().recovered_at_scan = scan;
    said += (said.empty() ? "" : "; ") + std::string("recovered at ") + Significant(t, 4) + " s";
  }
  return said;
}

namespace {
SlamOptions Refined(SlamOptions o) {
  o.refine.occupied_threshold = o.sensor.occupied_threshold;  // the map the filter weighs on
  return o;
}

MapperOptions WithMoments(const SlamOptions& o) {
  MapperOptions m = o.mapper;
  if (o.refine_estimate && o.mode == SlamMode::kFullSlam) {
    m.hit_moments = true;
    m.hit_range_power = o.refine.range_power;
  }
  return m;
}
}  // namespace

Slam::Slam(const SlamOptions& options, uint64_t seed)
    : options_(Refined(options)),
      mapper_(WithMoments(options)),
      action_(options.action),
      sensor_(options.sensor),
      no_map_sensor_(options.sensor),
      filter_(options.filter, seed) {
  if (options.mode == SlamMode::kGraphSlam) graph_ = std::make_unique<GraphSlam>(options.graph, options.mapper);
}

void Slam::SetMap(OccupancyGrid map) {
  mapper_.Reset(std::move(map));
  sensor_stale_ = true;
  filter_.SetFreeSpace(mapper_.map());
  ResetGate();
}

void Slam::Initialize(const motion::Pose2D& pose, const motion::Pose2D& odometry, double sigma_xy_m,
                      double sigma_theta_rad) {
  filter_.InitializeAt(pose, sigma_xy_m, sigma_theta_rad);
  if (graph_) graph_->Initialize(pose, odometry);
  last_odometry_ = odometry;
  last_estimate_ = pose;
  initialized_ = true;
}

void Slam::InitializeGlobal(const motion::Pose2D& odometry) {
  if (options_.mode != SlamMode::kLocalization) {
    throw std::logic_error("global localization needs localization mode and a known map");
  }
  filter_.InitializeGlobal();
  last_odometry_ = odometry;
  last_estimate_ = filter_.status().pose;
  initialized_ = true;
}

SlamStep Slam::ProcessScan(const std::vector<ScanRay>& rays, const motion::Pose2D& odometry,
                           const motion::Pose2D* reference, const OdometryDoubt& doubt, double time_s) {
  if (!initialized_) throw std::logic_error("SLAM: ProcessScan before Initialize");
  SlamStep out;
  if (graph_) {
    out.pose = graph_->ProcessScan(rays, odometry, doubt, time_s);
    out.filter_updated = true;
    return out;
  }
  if (options_.mode == SlamMode::kMappingOnly) {
    if (!reference) throw std::invalid_argument("mapping-only SLAM needs a reference pose per scan");
    out.pose = *reference;
    mapper_.Insert(rays, out.pose);
    return out;
  }
  // The filter moves only once odometry moved enough; in between the pose follows odometry.
  const bool moved = action_.Moved(last_odometry_, odometry) || !filter_.status().converged;
  if (moved && localization_on_) {
    const bool weigh = options_.mode == SlamMode::kLocalization || options_.mode == SlamMode::kFullSlam;
    if (weigh && sensor_stale_) {
      sensor_.SetMap(mapper_.map());
      sensor_stale_ = false;
    }
    const SensorModel& model = weigh ? sensor_ : no_map_sensor_;
    const ScanPoints points = model.Prepare(rays);
    const OdometryStep step = ActionModel::StepBetween(last_odometry_, odometry);
    filter_.Update(action_, step, model, points);
    last_odometry_ = odometry;
    last_estimate_ = weigh && options_.refine_estimate ? RefineEstimate(rays) : filter_.status().pose;
    out.filter_updated = true;
  }
  out.status = filter_.status();
  out.pose = last_estimate_.Compose(last_odometry_.Inverse().Compose(odometry));
  if (options_.mode != SlamMode::kLocalization && mapping_on_) {
    // The gate's map is the sensor model's, rebuilt at filter updates: with localization off it
    // may be far behind the map, so nothing is gated then.
    out.gated = options_.mode == SlamMode::kFullSlam && localization_on_ && Gate(rays, out.pose);
    if (!out.gated) {
      mapper_.Insert(rays, out.pose);
      sensor_stale_ = true;
    }
  }
  return out;
}

motion::Pose2D Slam::RefineEstimate(const std::vector<ScanRay>& rays) {
  const FilterStatus& st = filter_.status();
  const motion::Pose2D estimate = st.pose;
  if (!st.converged || st.lost || st.relocalized) return estimate;
  const std::vector<NdtPoint> hits = NdtPoints(rays);
  const NdtResult r = RefineNdt(mapper_.map(), mapper_.moments(), hits, estimate, options_.refine);
  // Taken where a quarter of the scan or more lies on the map's hits, and within three of the
  // priors' deviations: a scan that does not fit (corrupt, misplaced, the world changed) moves nothing.
  const NdtOptions& o = options_.refine;
  const bool fits = hits.size() >= 10 && r.points_used >= 0.25 * hits.size();
  const bool near = o.translation_weight <= 0 || o.rotation_weight <= 0 ||
                    (std::hypot(r.pose.x - estimate.x, r.pose.y - estimate.y) * o.translation_weight <= 3.0 &&
                     std::abs(motion::WrapAngle(r.pose.theta - estimate.theta)) * o.rotation_weight <= 3.0);
  if (!fits || !near) return estimate;
  filter_.Shift(r.pose.Compose(estimate.Inverse()));
  ++refined_;
  return r.pose;
}

void Slam::ResetGate() {
  recent_fits_.clear();
  gated_in_row_ = 0;
}

bool Slam::Gate(const std::vector<ScanRay>& rays, const motion::Pose2D& pose) {
  constexpr size_t kHistory = 15, kMinHistory = 10;
  // The map the sensor model holds may be a few scans old (it is rebuilt at filter updates): for
  // telling a collapse from a fit, that is the same map.
  if (options_.gate_fit_ratio <= 0 || !sensor_.has_map()) return false;
  const ScanPoints points = sensor_.Prepare(rays);
  if (points.size() == 0) return false;
  const double fit = sensor_.InlierFraction(pose, points);
  if (recent_fits_.size() >= kMinHistory && gated_in_row_ < options_.gate_max_scans) {
    std::vector<double> v(recent_fits_.begin(), recent_fits_.end());
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    if (fit < options_.gate_fit_ratio * v[v.size() / 2]) {
      ++gated_in_row_;
      ++scans_gated_;
      return true;
    }
  }
  gated_in_row_ = 0;
  recent_fits_.push_back(fit);
  if (recent_fits_.size() > kHistory) recent_fits_.pop_front();
  return false;
}

void Slam::SetMapping(bool on) {
  if (graph_) throw std::invalid_argument("graph SLAM maps every scan: its mapping cannot be switched");
  if (options_.mode == SlamMode::kLocalization && on) {
    throw std::invalid_argument("localization keeps its known map: it does not map");
  }
  mapping_on_ = on;
  ResetGate();
}

void Slam::SetLocalization(bool on) {
  if (graph_) throw std::invalid_argument("graph SLAM matches every scan: its localization cannot be switched");
  if (options_.mode == SlamMode::kMappingOnly) {
    throw std::invalid_argument("mapping-only SLAM takes its poses from a reference: it does not localize");
  }
  localization_on_ = on;
  ResetGate();
}

void Slam::ClearMap() {
  if (graph_) throw std::invalid_argument("graph SLAM's map is its graph's: it cannot be cleared");
  if (options_.mode == SlamMode::kLocalization) throw std::invalid_argument("localization keeps its known map");
  const OccupancyGrid& m = mapper_.map();
  mapper_.Reset(OccupancyGrid(m.width(), m.height(), m.resolution(), m.origin_x(), m.origin_y(), 0));
  sensor_stale_ = true;
  ResetGate();
}

void Slam::Finish() {
  if (graph_) graph_->Finish();
}

std::vector<motion::Pose2D> Slam::Trajectory() const {
  return graph_ ? graph_->Trajectory() : std::vector<motion::Pose2D>{};
}

}  // namespace mbot::mapping
