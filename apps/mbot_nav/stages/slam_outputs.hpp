// What the `slam` stage recorded over a run, and the writer of its outputs: the map (.map, PGM +
// YAML, a PNG with the SLAM, odometry and ground-truth paths, an OctoMap), the trajectories as TUM,
// slam_scans.csv and metrics.json (ATE per axis under each alignment, global localization,
// kidnapping, timing, map consistency).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "../stage.hpp"
#include "mbot/mapping/slam.hpp"
#include "mbot/motion/pose2d.hpp"
#include "slam_config.hpp"

namespace mbot::app {

// One processed scan.
struct ScanRecord {
  int64_t t_us = 0;
  motion::Pose2D slam, odometry;
  bool updated = false;
  mapping::FilterStatus status;
  double update_ms = 0;
  int64_t latency_us = 0;
  double rss_mb = 0;  // the process's resident memory, sampled every 64 scans (soak runs watch it)
  // The truth and the reference at the scan's time, once their series have passed it (the series
  // are trimmed behind the scans, so these are kept here).
  std::optional<motion::Pose2D> truth, reference;
};

// A scan kept for the map-consistency metric: its record's index and its points.
struct KeptScan {
  size_t record = 0;
  mapping::ScanPoints points;
};

struct SlamRun {
  const SlamStageOptions* options = nullptr;
  const mapping::Slam* slam = nullptr;
  const std::vector<ScanRecord>* records = nullptr;
  const std::vector<motion::TimedPose>* ground_truth = nullptr;  // the recent part, for records not yet paired
  const std::vector<motion::TimedPose>* reference = nullptr;
  const mapping::SlamEventTracker* events = nullptr;
  const std::vector<KeptScan>* scan_points = nullptr;  // a uniform sample of the records, for consistency
  const std::vector<motion::Pose2D>* particle_snapshots = nullptr;
  int64_t first_t_us = -1, last_t_us = -1, kidnapped_at_us = -1;
  int skipped_scans = 0;
  double wall_s = 0;
};

void WriteSlamOutputs(const RunContext& ctx, bool interrupted, const SlamRun& run);

}  // namespace mbot::app
