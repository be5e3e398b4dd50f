// SLAM on an event stream: the front end — which channels, each message placed at its time (its own
// stamp when the channel's stamps share the log's clock), the pose series (odometry from an odometry
// channel or integrated encoder ticks, made continuous across robot restarts and perturbed when
// asked; ground truth; reference), every scan deskewed with the odometry — and the policies: how the
// filter starts (origin, odometry, ground truth, reference, a pose, global; a resumed checkpoint's
// pose moved by the odometry since), when a checkpoint is due, and what is published (the pose every
// scan, SLAM's status on change, the particles and the map every k-th scan). The back end is
// mapping::Slam in whichever mode (particle filter, graph SLAM): the caller never asks which.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "mbot/common/strided_sample.hpp"
#include "mbot/mapping/moving_scan.hpp"
#include "mbot/mapping/scan_perturbation.hpp"
#include "mbot/mapping/slam.hpp"
#include "mbot/motion/odometry_continuity.hpp"
#include "mbot/motion/odometry_perturbation.hpp"
#include "mbot/motion/pose2d.hpp"
#include "mbot/motion/wheel_odometry.hpp"
#include "mbot/msgs/events.hpp"

namespace mbot::config {
class Section;
}

namespace mbot::mapping {

struct SlamSessionOptions {
  SlamOptions slam;
  ScanOptions scan;
  std::string known_map_name = "the known map";  // in messages (the stage's map_file)
  // Inputs.
  std::string lidar_channel, odometry_channel, ground_truth_channel, reference_channel;  // "" = first seen
  bool encoder_odometry = false;  // odometry from encoder ticks instead of an odometry channel
  motion::WheelOdometryOptions wheels;
  bool mapping_poses_from_reference = false;  // mapping-only: reference channel instead of ground truth
  bool lidar_pose_from_scan = true;           // the sensor pose the source gives (rawlog, CARMEN), else lidar_pose
  motion::Pose2D lidar_pose;
  std::string time_base = "event";  // event | stamp | auto
  BeamTiming beam_timing = BeamTiming::kAuto;
  int64_t lidar_time_offset_us = 0;
  double max_pose_gap_s = 0.5;
  // Start.
  std::string initial = "origin";  // origin | odometry | ground_truth | reference | global | pose
  motion::Pose2D initial_pose;
  double initial_sigma_xy = 0.0, initial_sigma_theta = 0.0;
  std::optional<motion::Pose2D> resume_odometry;  // resuming: the odometry the checkpoint was written at
  double checkpoint_every_s = 0.0;                // 0: no checkpoints
  // Perturbations for robustness tests.
  motion::OdometryPerturbationOptions perturbation;
  int scan_every = 1;                         // use every k-th scan (robustness tests drop the others)
  ScanPerturbationOptions scan_perturbation;  // glass and people
  // What is published, and kept for pictures.
  int particles_every = 0;          // keep the particles every k-th scan, for the map picture (0: never)
  int publish_particles_every = 0;  // emit SLAM_PARTICLES every k-th scan (0: never)
  int publish_map_every = 5;        // emit the map every k-th scan (0: never)
};

// The front end's and the policies' keys of a `slam` section (the back end's too: ParseSlamOptions).
// `initial_pose` = global needs mode = localization; resuming is the caller's (it reads the file).
SlamSessionOptions ParseSlamSessionOptions(config::Section& section);

// The session's inputs from the event stream: the channels it listens to (the first of a kind
// unless the options name one), the pose series and the scans waiting for their poses to arrive.
class SlamInputs {
 public:
  struct Scan {
    int64_t t_us = 0;          // the scan's time (its last beam); lidar_time_offset is added on use
    int64_t previous_us = -1;  // the scan before, or -1
    int64_t latency_us = 0;    // arrival time − stamp when both share a clock, else 0
    int64_t stamp_us = 0;      // the scan message's own stamp (its event time when it has none)
    msgs::LidarScan scan;
  };

  // Keeps a reference to `options`, which must outlive it.
  SlamInputs(const SlamSessionOptions& options, uint64_t seed);
  SlamInputs(const SlamInputs&) = delete;
  SlamInputs& operator=(const SlamInputs&) = delete;

  // Takes one event of the stream; false when it is of no interest to SLAM.
  bool Add(const msgs::Event& in);
  // The oldest waiting scan whose poses have arrived (any waiting scan when `at_end`), or nullptr.
  const Scan* ReadyScan(bool at_end) const;
  void PopScan() { pending_.pop_front(); }

  // The poses scans are placed at: odometry, or in mapping-only mode the given poses.
  const std::vector<motion::TimedPose>& poses() const;
  const std::vector<motion::TimedPose>& odometry() const { return odometry_; }
  const std::vector<motion::TimedPose>& ground_truth() const { return ground_truth_; }
  const std::vector<motion::TimedPose>& reference() const { return reference_; }
  int64_t first_t_us() const { return first_t_us_; }
  int64_t last_t_us() const { return last_t_us_; }
  const std::string& lidar_channel() const { return lidar_channel_; }
  const std::string& odometry_channel() const { return odometry_channel_; }
  // Scans taken from the lidar channel, and every odometry channel seen (with its message count).
  int64_t scans_seen() const { return scans_seen_; }
  const std::map<std::string, int64_t>& odometry_channels_seen() const { return odometry_seen_; }
  int64_t kidnapped_at_us() const { return perturbation_.kidnapped_at_us(); }
  int odometry_restarts() const { return continuity_.restarts(); }
  const motion::OdometryContinuity& continuity() const { return continuity_; }
  // Whether the poses between `from_us` and `to_us` (with the readings around them) leave a gap
  // longer than `max_gap_us` that ends after from_us (and the longest such gap), or the odometry
  // restarted (a zeroed jump) in (from_us, to_us].
  OdometryDoubt PosesDoubtful(int64_t from_us, int64_t to_us, int64_t max_gap_us) const;

  // Drops the pose series' entries before t_us, keeping the last one before it (an interpolation
  // at t_us still has both neighbours), so a run of any length keeps bounded memory. Cheap to call
  // often: it trims only once a few thousand entries are due.
  void TrimBefore(int64_t t_us);

 private:
  const msgs::Event& Retime(const msgs::Event& ev, msgs::Event* copy);
  bool Accept(std::string* chosen, const std::string& wanted, const msgs::Event& ev);
  bool ScanLineOdometry(const std::string& channel) const;
  // `stamp_us`: the message's own stamp (0: none), which tells a duplicate when t_us is its arrival.
  void AddOdometry(int64_t t_us, const motion::Pose2D& raw, int64_t stamp_us);

  const SlamSessionOptions& o_;
  motion::OdometryContinuity continuity_;
  motion::OdometryPerturbation perturbation_;
  std::optional<motion::WheelOdometry> wheel_odometry_;
  std::string odometry_channel_, encoder_channel_, truth_channel_, reference_channel_, lidar_channel_;
  std::vector<motion::TimedPose> odometry_, ground_truth_, reference_;
  std::deque<Scan> pending_;
  std::map<std::string, bool> stamp_channels_;  // channel → its stamps share the log's clock
  int64_t previous_scan_us_ = -1;
  int64_t scans_seen_ = 0;
  std::map<std::string, int64_t> odometry_seen_;
  long long stamp_outliers_ = 0;                     // stamps far from their arrival, placed at the arrival instead
  long long stamps_ahead_ = 0;                       // stamps well ahead of their channel's usual lag: dropped
  std::map<std::string, std::deque<int64_t>> lags_;  // per stamped channel: the last arrival − stamp
  std::deque<int64_t> restart_times_;                // the last restarts the continuity check zeroed, oldest first
  int64_t first_t_us_ = -1, last_t_us_ = -1;
};

// One processed scan.
struct ScanRecord {
  int64_t t_us = 0;
  int64_t stamp_us = 0;  // the scan's own stamp (tum_time = stamp)
  motion::Pose2D slam, odometry;
  bool updated = false;
  FilterStatus status;
  double update_ms = 0;
  int64_t latency_us = 0;
  double rss_mb = 0;  // the process's resident memory, sampled every 64 scans (soak runs watch it)
  // The truth and the reference at the scan's time, once their series have passed it (the series
  // are trimmed behind the scans, so these are kept here).
  std::optional<motion::Pose2D> truth, reference;
};

// The scans kept for the map-consistency metric: each one's record index, points and pose.
struct SampledScan {
  motion::Pose2D pose;
  ScanPoints points;
};
using ScanSample = StridedSample<SampledScan>;

// What a checkpoint holds besides the map (Slam::map()).
struct SlamCheckpointState {
  motion::Pose2D pose, odometry;
  double t_s = 0;  // since the stream's start
  long long scans = 0;
};

class SlamSession {
 public:
  // `known_map`: localization's map, the map a resumed run starts from, or (graph SLAM with
  // initial_pose = global) the finished map the first scan is found on by a whole-map search.
  SlamSession(const SlamSessionOptions& options, uint64_t seed, std::optional<OccupancyGrid> known_map);
  SlamSession(const SlamSession&) = delete;
  SlamSession& operator=(const SlamSession&) = delete;

  // One event of the stream; what SLAM publishes in answer (SLAM_POSE, SLAM_STATUS, SLAM_PARTICLES,
  // SLAM_MAP) is appended to `out`, in order. A SlamControl (a person at the viewer) switches
  // mapping or localization, or clears the map (Slam::SetMapping …); the next scan's status says what holds.
  void Add(const msgs::Event& event, std::vector<msgs::Event>* out);
  // The scans still waiting, then the back end's last word (graph SLAM closes its last loops and
  // solves: the records take the optimised poses).
  void Finish(std::vector<msgs::Event>* out);
  // Called once every checkpoint_every_s of the stream's time, after the scan that made it due, with
  // the map then (the caller writes the files).
  void OnCheckpoint(std::function<void(const SlamCheckpointState&, const OccupancyGrid&)> write) {
    on_checkpoint_ = std::move(write);
  }

  // Streams the records: each goes to `sink` once its pose is final and its truth and reference
  // are paired — full SLAM and localization: as soon as both series have passed it, or once it is
  // min(4 × max_pose_gap_s, 60 s) + 1 s old (a series that stopped or never started: 3 s by
  // default); graph SLAM: all at Finish, with the optimised poses — and is then dropped, so a run of
  // any length holds a bounded number. Without a sink every record is kept (records()).
  void StreamRecords(std::function<void(const ScanRecord&)> sink) { sink_ = std::move(sink); }

  const SlamSessionOptions& options() const { return o_; }
  const Slam& slam() const { return slam_; }
  const SlamInputs& inputs() const { return inputs_; }
  const std::deque<ScanRecord>& records() const { return records_; }  // those not streamed yet
  size_t scans_processed() const { return released_ + records_.size(); }
  const std::optional<ScanRecord>& last_record() const { return last_record_; }
  const SlamEventTracker& events() const { return events_; }
  const std::vector<ScanSample::Item>& scan_points() const { return scan_sample_.items(); }
  const std::vector<motion::Pose2D>& particle_snapshots() const { return particle_snapshots_; }
  int skipped_scans() const { return skipped_scans_; }
  const ScanPerturbation& scan_perturbation() const { return scan_perturbation_; }

 private:
  void ProcessReadyScans(bool at_end, std::vector<msgs::Event>* out);
  void Control(const msgs::SlamControl& control);
  void ProcessScan(const SlamInputs::Scan& p, int64_t t_end, std::vector<msgs::Event>* out);
  bool Initialize(int64_t t_us, const motion::Pose2D& odometry, const std::vector<ScanRay>& rays);
  void Publish(const ScanRecord& r, std::vector<msgs::Event>* out);
  void PairRecordsAndTrim(int64_t scan_start_us, int64_t max_gap_us);
  void ReleaseFront(int64_t max_gap_us);

  const SlamSessionOptions& o_;
  Slam slam_;
  std::optional<OccupancyGrid> global_map_;  // graph SLAM: the map the first scan is searched on
  SlamInputs inputs_;
  SlamEventTracker events_;
  SensorModel consistency_model_;
  ScanPerturbation scan_perturbation_;
  ScanSample scan_sample_{2048};  // the map-consistency metric's scans: bounded for any run length
  std::deque<ScanRecord> records_;
  size_t paired_truth_ = 0, paired_reference_ = 0;  // records before these have their truth / reference
  size_t released_ = 0;                             // records handed to the sink and dropped
  std::function<void(const ScanRecord&)> sink_;
  std::optional<ScanRecord> last_record_;
  std::vector<motion::Pose2D> particle_snapshots_;
  std::optional<SlamState> published_state_;
  int skipped_scans_ = 0;
  double rss_mb_ = 0;
  int64_t last_checkpoint_us_ = -1;
  int64_t last_scan_end_us_ = -1;  // the last scan given to SLAM
  std::function<void(const SlamCheckpointState&, const OccupancyGrid&)> on_checkpoint_;
  bool status_due_ = false, map_due_ = false;  // after a person's SlamControl
};

// Why a session processed no scan, in words that name the channels (the lidar's, the odometry's
// and what the log had instead), for the error that ends such a run.
std::string NoScanProcessedReason(const SlamSession& session);

}  // namespace mbot::mapping
