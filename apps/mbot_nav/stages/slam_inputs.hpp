// The `slam` stage's inputs, from the event stream: the channels it listens to (the first of a
// kind unless the options name one), each message placed at its time (its own stamp when the
// channel's stamps share the log's clock), the pose series (odometry — from an odometry channel or
// integrated encoder ticks, perturbed when asked —, ground truth, reference) and the scans waiting
// for their poses to arrive.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "mbot/drivers/events.hpp"
#include "mbot/motion/odometry_continuity.hpp"
#include "mbot/motion/odometry_perturbation.hpp"
#include "mbot/motion/wheel_odometry.hpp"
#include "slam_config.hpp"

namespace mbot::app {

class SlamInputs {
 public:
  struct Scan {
    int64_t t_us = 0;          // the scan's time (its last beam); lidar_time_offset is added on use
    int64_t previous_us = -1;  // the scan before, or -1
    int64_t latency_us = 0;    // arrival time − stamp when both share a clock, else 0
    int64_t stamp_us = 0;      // the scan message's own stamp (its event time when it has none)
    drivers::LidarScan scan;
  };

  // Keeps a reference to `options`, which must outlive it.
  SlamInputs(const SlamStageOptions& options, uint64_t seed);
  SlamInputs(const SlamInputs&) = delete;
  SlamInputs& operator=(const SlamInputs&) = delete;

  // Takes one event of the stream; false when it is of no interest to SLAM.
  bool Add(const drivers::Event& in);
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
  int64_t kidnapped_at_us() const { return perturbation_.kidnapped_at_us(); }
  int odometry_restarts() const { return continuity_.restarts(); }

  // Drops the pose series' entries before t_us, keeping the last one before it (an interpolation
  // at t_us still has both neighbours), so a run of any length keeps bounded memory. Cheap to call
  // often: it trims only once a few thousand entries are due.
  void TrimBefore(int64_t t_us);

 private:
  const drivers::Event& Retime(const drivers::Event& ev, drivers::Event* copy);
  bool Accept(std::string* chosen, const std::string& wanted, const drivers::Event& ev);
  void AddOdometry(int64_t t_us, const motion::Pose2D& raw);

  const SlamStageOptions& o_;
  motion::OdometryContinuity continuity_;
  motion::OdometryPerturbation perturbation_;
  std::optional<motion::WheelOdometry> wheel_odometry_;
  std::string odometry_channel_, encoder_channel_, truth_channel_, reference_channel_, lidar_channel_;
  std::vector<motion::TimedPose> odometry_, ground_truth_, reference_;
  std::deque<Scan> pending_;
  std::map<std::string, bool> stamp_channels_;  // channel → its stamps share the log's clock
  int64_t previous_scan_us_ = -1;
  long long stamp_outliers_ = 0;  // stamps far from their arrival, placed at the arrival instead
  int64_t first_t_us_ = -1, last_t_us_ = -1;
};

}  // namespace mbot::app
