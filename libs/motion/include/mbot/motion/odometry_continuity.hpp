// Odometry that survives a robot restart. When the MBot's firmware (or the simulated robot) restarts,
// its odometry starts again from zero while the robot stays where it was: to SLAM and the mission
// that looks like the robot jumping metres in one message. OdometryContinuity spots a step no robot
// can make between two messages (longer than max_step_m plus max_speed_m_s × the gap, or turning more
// than max_turn_rad plus max_turn_rate_rad_s × the gap). When the next message agrees with the jumped-to
// pose it was a restart: the step counts as no motion and later messages continue from the pose
// before it. When the next message agrees with the pose before the jump it was one corrupt message,
// dropped (a pose beyond ±1e5 m is always that).
#pragma once

#include <cstdint>

#include "mbot/motion/pose2d.hpp"

namespace mbot::motion {

struct OdometryContinuityOptions {
  double max_step_m = 0.3;           // a step this long between two messages is a restart…
  double max_speed_m_s = 1.5;        // …plus what the robot could drive in the gap (MBot: < 1 m/s)
  double max_turn_rad = 1.0;         // a turn this large between two messages is a restart…
  double max_turn_rate_rad_s = 6.0;  // …plus what it could turn in the gap
};

class OdometryContinuity {
 public:
  explicit OdometryContinuity(const OdometryContinuityOptions& options = {}) : o_(options) {}

  // The continuous pose for a raw odometry message at t_us.
  Pose2D Update(int64_t t_us, const Pose2D& raw);

  // Restarts seen so far, and the last one's time (−1 before any); single corrupt messages dropped.
  int restarts() const { return restarts_; }
  int64_t last_restart_us() const { return last_restart_us_; }
  int outliers() const { return outliers_; }

 private:
  bool Jump(const Pose2D& from, const Pose2D& to, int64_t gap_us) const;

  OdometryContinuityOptions o_;
  bool started_ = false;
  int64_t last_t_us_ = 0;
  Pose2D last_raw_;
  Pose2D offset_;  // continuous = offset ⊕ raw
  int restarts_ = 0, outliers_ = 0;
  int64_t last_restart_us_ = -1;
  bool candidate_ = false;  // the last message jumped: a restart if the next one agrees with it
  Pose2D candidate_raw_;
  int64_t candidate_t_us_ = 0;
};

}  // namespace mbot::motion
