// The writer of the `slam` stage's outputs from what its session recorded: the map (.map, PGM +
// YAML, a PNG with the SLAM, odometry and ground-truth paths, an OctoMap), the trajectories as TUM,
// slam_scans.csv and metrics.json (ATE per axis under each alignment, global localization,
// kidnapping, timing, map consistency).
#pragma once

#include <cstdint>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mbot/common/atomic_file.hpp"
#include "mbot/mapping/slam_session.hpp"
#include "mbot/motion/pose2d.hpp"
#include "slam_config.hpp"
#include "stages.hpp"

namespace mbot::app {

// The per-scan outputs, streamed as the session releases its records (SlamSession::StreamRecords),
// so a run of any length keeps flat memory: slam.tum, odometry.tum, ground_truth.tum and
// slam_scans.csv (each renamed into place at Commit, whole, or removed), and a spool beside them of
// what the scores need — the poses paired with the truth, the timings — which WriteSlamOutputs
// reads back from disk at the end (the ATE in two passes; the relations, the medians and the map's
// paths need the whole run then, about 100 bytes a scan, freed once written).
class SlamRecordWriter {
 public:
  SlamRecordWriter(const std::string& dir, const SlamStageOptions& options);
  ~SlamRecordWriter();
  SlamRecordWriter(const SlamRecordWriter&) = delete;
  SlamRecordWriter& operator=(const SlamRecordWriter&) = delete;

  // One released record; `first_t_us` is the stream's first time (the scoring window's origin).
  void Add(const mapping::ScanRecord& r, int64_t first_t_us);
  // The trajectories and slam_scans.csv into place (ground_truth.tum only when a truth came).
  void Commit();

  // What the spool holds for one record.
  struct Spooled {
    int64_t t_us = 0, tum_t_us = 0, latency_us = 0;
    motion::Pose2D slam, odometry, truth, reference;
    uint8_t has_truth = 0, has_reference = 0, scored = 0, updated = 0;
    float update_ms = 0, ess = 0;
  };
  // Calls `f` on every spooled record, in order (readable after Commit, as often as needed).
  void ForEach(const std::function<void(const Spooled&)>& f);
  size_t records() const { return records_; }
  int unscored_late() const { return unscored_late_; }
  bool has_truth() const { return truth_tum_ != nullptr; }

 private:
  const SlamStageOptions& o_;
  std::string dir_, truth_name_, spool_path_;
  std::unique_ptr<AtomicFileWriter> slam_tum_, odometry_tum_, scans_csv_, truth_tum_;
  std::fstream spool_;  // unlinked once open: nothing is left behind, however the run ends
  size_t records_ = 0;
  int unscored_late_ = 0;
};

// Writes the map, metrics.json and the rest of a finished session's outputs, after committing the
// streamed ones.
void WriteSlamOutputs(const RunContext& ctx, bool interrupted, const SlamStageOptions& options,
                      const mapping::SlamSession& session, SlamRecordWriter& records, double wall_s);

}  // namespace mbot::app
