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
#include "mbot/common/strided_sample.hpp"
#include "mbot/mapping/slam.hpp"
#include "mbot/motion/pose2d.hpp"
#include "slam_config.hpp"
#include "slam_inputs.hpp"

namespace mbot::app {

// One processed scan.
struct ScanRecord {
  int64_t t_us = 0;
  int64_t stamp_us = 0;  // the scan's own stamp (tum_time = stamp)
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

// The scans kept for the map-consistency metric: each one's record index and points.
using ScanSample = StridedSample<mapping::ScanPoints>;

// Records before these have their truth and reference poses.
struct RecordPairing {
  size_t truth = 0, reference = 0;
};

// Records take their truth and reference poses once those series have passed their time; the
// series are then trimmed behind both the records still waiting and the scan starting at
// `scan_start_us`, so a run of any length keeps bounded memory.
void PairRecordsAndTrim(SlamInputs* inputs, std::vector<ScanRecord>* records, RecordPairing* paired,
                        int64_t scan_start_us, int64_t max_gap_us);

struct SlamRun {
  const SlamStageOptions* options = nullptr;
  const mapping::Slam* slam = nullptr;
  const std::vector<ScanRecord>* records = nullptr;
  const std::vector<motion::TimedPose>* ground_truth = nullptr;  // the recent part, for records not yet paired
  const std::vector<motion::TimedPose>* reference = nullptr;
  const mapping::SlamEventTracker* events = nullptr;
  const std::vector<ScanSample::Item>* scan_points = nullptr;  // a uniform sample of the records, for consistency
  const std::vector<motion::Pose2D>* particle_snapshots = nullptr;
  int64_t first_t_us = -1, last_t_us = -1, kidnapped_at_us = -1;
  int skipped_scans = 0;
  double wall_s = 0;
};

void WriteSlamOutputs(const RunContext& ctx, bool interrupted, const SlamRun& run);

}  // namespace mbot::app
