// A SLAM run's per-scan outputs, streamed as the session releases its records
// (SlamSession::StreamRecords), so a run of any length keeps flat memory while it runs:
// slam.tum, odometry.tum, ground_truth.tum and slam_scans.csv (each renamed into place at Commit,
// whole, or removed), and a spool beside them of what the scores need — the poses paired with the
// truth, the timings — which ReadBack reads from disk at the end (the ATE in two passes; the
// relations, the medians and the map's paths need the whole run then, about 100 bytes a scan).
#pragma once

#include <cstdint>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mbot/mapping/slam_session.hpp"
#include "mbot/motion/pose2d.hpp"
#include "mbot/motion/trajectory_error.hpp"

namespace mbot {
class AtomicFileWriter;
}

namespace mbot::mapping {

struct SlamRecordOptions {
  std::string mode;                  // named in slam.tum's header ("SLAM (<mode>)")
  bool tum_stamps = false;           // the TUM files and the relations use the scans' own stamps
  bool truth_is_reference = false;   // score against the reference (CARMEN's corrected poses)
  int64_t score_from_us = 0;         // the ATE counts scans from this long after the stream's start
  int64_t score_max_latency_us = 0;  // ... that arrived at most this late (0: all)
};

// What the spool says of the whole run, read back at its end.
struct SlamRecordSummary {
  std::optional<motion::TrajectoryErrors> slam, odometry, reference;  // against the truth, when scored
  std::vector<motion::Pose2D> slam_path, odometry_path, truth_path;   // every scan's (the map's picture)
  std::vector<motion::TimedPose> relation_path;                       // SLAM at the TUM times, when asked
  std::vector<double> update_ms, filter_ms, ess;                      // every scan's; filter updates'
  int updates = 0;
};

class SlamRecordWriter {
 public:
  // Creates the files in `dir` (removing what a killed run there left of them).
  SlamRecordWriter(const std::string& dir, const SlamRecordOptions& options);
  ~SlamRecordWriter();
  SlamRecordWriter(const SlamRecordWriter&) = delete;
  SlamRecordWriter& operator=(const SlamRecordWriter&) = delete;

  // One released record; `first_t_us` is the stream's first time (the scoring window's origin).
  void Add(const ScanRecord& r, int64_t first_t_us);
  // The trajectories and slam_scans.csv into place (ground_truth.tum only when a truth came).
  void Commit();
  // The spool read back (after Commit): the ATE under each alignment in two passes, the paths,
  // the timings, and the SLAM path at the TUM times when `relation_path`.
  SlamRecordSummary ReadBack(bool relation_path);

  size_t records() const { return records_; }
  int unscored_late() const { return unscored_late_; }
  bool has_truth() const { return truth_tum_ != nullptr; }

 private:
  struct Spooled {
    int64_t t_us = 0, tum_t_us = 0, latency_us = 0;
    motion::Pose2D slam, odometry, truth, reference;
    uint8_t has_truth = 0, has_reference = 0, scored = 0, updated = 0;
    float update_ms = 0, ess = 0;
  };
  void ForEach(const std::function<void(const Spooled&)>& f);

  SlamRecordOptions o_;
  std::string dir_, truth_name_, spool_path_;
  std::unique_ptr<AtomicFileWriter> slam_tum_, odometry_tum_, scans_csv_, truth_tum_;
  std::fstream spool_;  // unlinked once open: nothing is left behind, however the run ends
  size_t records_ = 0;
  int unscored_late_ = 0;
};

}  // namespace mbot::mapping
