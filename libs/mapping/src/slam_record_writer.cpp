#include "mbot/mapping/slam_record_writer.hpp"

#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "mbot/common/atomic_file.hpp"
#include "mbot/motion/tum.hpp"

namespace mbot::mapping {

using motion::Pose2D;
using motion::TumHeader;
using motion::TumLine;

SlamRecordWriter::SlamRecordWriter(const std::string& dir, const SlamRecordOptions& options)
    : o_(options),
      dir_(dir + "/"),
      truth_name_(options.truth_is_reference ? "reference" : "ground truth"),
      spool_path_(TempPathFor(dir_ + "slam_records.spool")) {
  // What a run killed in this folder left (a SIGKILL renames nothing): gone before this one starts.
  for (const char* name : {"slam.tum", "odometry.tum", "ground_truth.tum", "slam_scans.csv"})
    RemoveStaleTempFiles(dir_ + name);
  slam_tum_ = std::make_unique<AtomicFileWriter>(dir_ + "slam.tum");
  slam_tum_->stream() << TumHeader("SLAM (" + options.mode + ")");
  odometry_tum_ = std::make_unique<AtomicFileWriter>(dir_ + "odometry.tum");
  odometry_tum_->stream() << TumHeader("odometry at the scan times");
  scans_csv_ = std::make_unique<AtomicFileWriter>(dir_ + "slam_scans.csv");
  scans_csv_->stream() << "t_s,x,y,theta,filter_updated,particles,ess,spread_m,inlier_fraction,fit_ratio,injected,"
                          "lost,converged,update_ms,rss_mb\n";
  spool_.open(spool_path_, std::ios::binary | std::ios::trunc | std::ios::in | std::ios::out);
  if (!spool_) throw std::runtime_error(spool_path_ + ": cannot create the slam stage's record spool");
  std::remove(spool_path_.c_str());  // the open stream keeps it; no name is left to clean up
}

SlamRecordWriter::~SlamRecordWriter() = default;

void SlamRecordWriter::Add(const ScanRecord& r, int64_t first_t_us) {
  Spooled sp;
  std::memset(static_cast<void*>(&sp), 0, sizeof sp);  // the padding too: the bytes go to disk
  sp.t_us = r.t_us;
  sp.tum_t_us = o_.tum_stamps ? r.stamp_us : r.t_us;
  sp.latency_us = r.latency_us;
  sp.slam = r.slam;
  sp.odometry = r.odometry;
  sp.updated = r.updated;
  sp.update_ms = static_cast<float>(r.update_ms);
  sp.ess = static_cast<float>(r.status.ess);
  slam_tum_->stream() << TumLine(sp.tum_t_us * 1e-6, r.slam.x, r.slam.y, r.slam.theta);
  odometry_tum_->stream() << TumLine(sp.tum_t_us * 1e-6, r.odometry.x, r.odometry.y, r.odometry.theta);
  char line[256];
  std::snprintf(line, sizeof line, "%.6f,%.4f,%.4f,%.5f,%d,%d,%.1f,%.4f,%.3f,%.3f,%d,%d,%d,%.3f,%.1f\n", r.t_us * 1e-6,
                r.slam.x, r.slam.y, r.slam.theta, r.updated, r.status.particles, r.status.ess, r.status.spread_m,
                r.status.inlier_fraction, r.status.fit_ratio, r.status.injected, r.status.lost, r.status.converged,
                r.update_ms, r.rss_mb);
  scans_csv_->stream() << line;
  // Each scan's pose against the truth at its time: within the scoring window and not too late.
  const std::optional<Pose2D>& truth = o_.truth_is_reference ? r.reference : r.truth;
  if (truth) {
    sp.has_truth = 1;
    sp.truth = *truth;
    if (!truth_tum_) {
      truth_tum_ = std::make_unique<AtomicFileWriter>(dir_ + "ground_truth.tum");
      truth_tum_->stream() << TumHeader(truth_name_ + " at the scan times");
    }
    truth_tum_->stream() << TumLine(sp.tum_t_us * 1e-6, truth->x, truth->y, truth->theta);
    const bool late = o_.score_max_latency_us > 0 && r.latency_us > o_.score_max_latency_us;
    unscored_late_ += late;
    sp.scored = r.t_us >= o_.score_from_us + first_t_us && !late;
    if (sp.scored && !o_.truth_is_reference && r.reference) sp.has_reference = 1, sp.reference = *r.reference;
  }
  spool_.write(reinterpret_cast<const char*>(&sp), sizeof sp);
  if (!spool_) throw std::runtime_error(spool_path_ + ": write failed (disk full?)");
  ++records_;
}

void SlamRecordWriter::Commit() {
  spool_.flush();
  if (!spool_) throw std::runtime_error(spool_path_ + ": write failed (disk full?)");
  slam_tum_->Commit();
  odometry_tum_->Commit();
  scans_csv_->Commit();
  if (truth_tum_) truth_tum_->Commit();
}

void SlamRecordWriter::ForEach(const std::function<void(const Spooled&)>& f) {
  spool_.flush();
  spool_.clear();
  spool_.seekg(0);
  Spooled sp;
  size_t n = 0;
  while (n < records_ && spool_.read(reinterpret_cast<char*>(&sp), sizeof sp)) f(sp), ++n;
  spool_.clear();
  spool_.seekp(0, std::ios::end);
  if (n != records_) {
    throw std::runtime_error(spool_path_ + ": read back " + std::to_string(n) + " of " + std::to_string(records_) +
                             " records");
  }
}

SlamRecordSummary SlamRecordWriter::ReadBack(bool relation_path) {
  using motion::AteAccumulator;
  using motion::AteAlignment;
  // Aligned, anchored and unaligned: the alignments in a first pass, the errors in a second.
  std::vector<AteAccumulator> slam, odometry, reference;
  for (auto* v : {&slam, &odometry, &reference})
    for (AteAlignment a : {AteAlignment::kBestFitSE2, AteAlignment::kFirstPose, AteAlignment::kNone})
      v->emplace_back(a);
  SlamRecordSummary s;
  ForEach([&](const Spooled& r) {
    s.slam_path.push_back(r.slam);
    s.odometry_path.push_back(r.odometry);
    if (r.has_truth) s.truth_path.push_back(r.truth);
    s.update_ms.push_back(r.update_ms);
    if (r.updated) ++s.updates, s.filter_ms.push_back(r.update_ms), s.ess.push_back(r.ess);
    if (relation_path) s.relation_path.push_back({r.tum_t_us, r.slam});
    if (!r.scored) return;
    for (int k = 0; k < 3; ++k) {
      slam[k].AddForAlignment(r.slam, r.truth);
      odometry[k].AddForAlignment(r.odometry, r.truth);
      if (r.has_reference) reference[k].AddForAlignment(r.reference, r.truth);
    }
  });
  ForEach([&](const Spooled& r) {
    if (!r.scored) return;
    for (int k = 0; k < 3; ++k) {
      slam[k].AddError(r.slam, r.truth);
      odometry[k].AddError(r.odometry, r.truth);
      if (r.has_reference) reference[k].AddError(r.reference, r.truth);
    }
  });
  auto errors = [](const std::vector<AteAccumulator>& a) -> std::optional<motion::TrajectoryErrors> {
    if (a[0].samples() == 0) return std::nullopt;
    return motion::TrajectoryErrors{a[0].Result(), a[1].Result(), a[2].Result()};
  };
  s.slam = errors(slam), s.odometry = errors(odometry), s.reference = errors(reference);
  return s;
}

}  // namespace mbot::mapping
