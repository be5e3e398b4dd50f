// Scan likelihood of a pose given a map. Two models:
//  - likelihood field (Thrun et al. §6.4): each ray's end point scores the Gaussian of its distance
//    to the nearest occupied cell, mixed with a uniform term for unexplained returns; distances come
//    from an exact distance transform of the map, folded into a per-cell table when the map is set;
//  - the botlab "simplified likelihood field": the end cell's log-odds when occupied, else a
//    fraction of the cell just before or after it along the ray.
// Both give log-likelihoods (scaled by `log_scale` to temper the correlation between beams) and
// need one table lookup per beam.
#pragma once

#include <vector>

#include "mbot/mapping/moving_scan.hpp"
#include "mbot/mapping/occupancy_grid.hpp"
#include "mbot/motion/pose2d.hpp"

namespace mbot::mapping {

enum class SensorModelKind { kLikelihoodField, kSimplifiedField };

struct SensorModelOptions {
  SensorModelKind kind = SensorModelKind::kLikelihoodField;
  int ray_stride = 1;          // use every k-th hit ray
  int occupied_threshold = 0;  // log-odds above this count as obstacles
  double log_scale = 1.0;      // multiplies the summed per-beam log-likelihood
  // Likelihood field.
  double sigma_m = 0.05;
  double max_distance_m = 0.5;  // distances are clamped here (also the value off the map)
  double random_weight = 0.05;  // uniform share for unexplained returns, relative to the Gaussian peak
  // Simplified likelihood field: log-likelihood per log-odds unit, and the weight of a neighbour cell.
  double odds_scale = 0.02;
  double neighbour_weight = 0.5;
  // A ray fits the map when its end lies within this distance of an obstacle (the "lost" test).
  double inlier_distance_m = 0.10;
  // Weigh eight beams per instruction (AVX2 gathers) where the processor has them. Either way the
  // sums are the same to the last bit: the lanes' order is fixed and nothing is fused.
  bool simd = true;
};

// The rays a sensor model uses: hit end points in the robot frame plus, for the simplified model,
// one cell-length step along each ray.
struct ScanPoints {
  std::vector<float> x, y, step_x, step_y;
  size_t size() const { return x.size(); }
};

class SensorModel {
 public:
  explicit SensorModel(const SensorModelOptions& options)
      : options_(options), use_simd_(options.simd && SimdAvailable()) {}
  // Builds the lookup tables for `map`; call again whenever the map changes. A map of the same
  // geometry as the last one only recomputes the distances near obstacles that appeared or vanished.
  void SetMap(const OccupancyGrid& map);
  bool has_map() const { return width_ > 0; }
  ScanPoints Prepare(const std::vector<ScanRay>& rays) const;
  double LogLikelihood(const motion::Pose2D& pose, const ScanPoints& scan) const;
  // Share of the scan's points that end within inlier_distance_m of an obstacle.
  double InlierFraction(const motion::Pose2D& pose, const ScanPoints& scan) const;
  const SensorModelOptions& options() const { return options_; }
  // Whether this processor runs the AVX2 path (options().simd asks for it).
  static bool SimdAvailable();

 private:
  void BuildLookup();
  void UpdateDistances(int x0, int y0, int x1, int y1);

  SensorModelOptions options_;
  bool use_simd_ = false;  // options_.simd on a processor that has AVX2, decided once
  int width_ = 0, height_ = 0;
  double resolution_ = 0.05, origin_x_ = 0, origin_y_ = 0;
  std::vector<float> table_;  // simplified field: per-cell scaled log-odds
  // Likelihood field: per-cell log-likelihood with a one-cell border holding the off-map value, so
  // the inner loop clamps its indices instead of branching: (width + 2) × (height + 2).
  std::vector<float> padded_;
  std::vector<uint8_t> inlier_;    // per cell: within inlier_distance_m of an obstacle
  float off_map_ = 0.0f;           // value of a point off the map
  std::vector<uint8_t> obstacle_;  // the obstacle mask the distance tables were built from
  int reach_cells_ = 0;            // distances beyond this many cells all score as "far"
  std::vector<float> field_lut_;   // likelihood-field value by squared distance in cells²
  std::vector<uint8_t> inlier_lut_;
};

}  // namespace mbot::mapping
