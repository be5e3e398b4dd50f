// Odometry that survives a robot restart. When the MBot's firmware (or the simulated robot) restarts,
// its odometry starts again from zero while the robot stays where it was: to SLAM and the mission
// that looks like the robot jumping metres in one message. OdometryContinuity spots a step no robot
// can make between two messages (longer than max_step_m plus max_speed_m_s × the gap, or turning more
// than max_turn_rad plus max_turn_rate_rad_s × the gap). When the next message agrees with the jumped-to
// pose it was a restart: the step counts as no motion and later messages continue from the pose
// before it. When the next message agrees with the pose before the jump it was one corrupt message,
// dropped (a pose beyond ±1e5 m, or a heading beyond ±1e5 rad, is always that). A jump that agrees
// with the message before the last one taken was no jump: the last one was corrupt, by less than a
// jump. The jump's own message again (stamped no later: a duplicate, as a faulty bus makes of a
// corrupt message too) confirms nothing.
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

  // The continuous pose for a raw odometry message at t_us; `stamp_us` (0: none) is the message's
  // own stamp when t_us is its arrival, so a duplicate (the same stamp) is known for one.
  Pose2D Update(int64_t t_us, const Pose2D& raw, int64_t stamp_us = 0);

  // Restarts seen so far, and the last one's time (−1 before any); single corrupt messages dropped.
  int restarts() const { return restarts_; }
  int64_t last_restart_us() const { return last_restart_us_; }
  // The last restart's raw poses: the last before the jump, the jumped-to one, and the one after it
  // that agreed with it (and their times).
  struct Restart {
    Pose2D before, jumped, confirmed;
    int64_t before_us = 0, jumped_us = 0, confirmed_us = 0;
  };
  const Restart& last_restart() const { return last_restart_; }
  int outliers() const { return outliers_; }
  int duplicates() const { return duplicates_; }  // of a jump, not taken as its confirmation

 private:
  bool Jump(const Pose2D& from, const Pose2D& to, int64_t gap_us) const;

  OdometryContinuityOptions o_;
  bool started_ = false;
  int64_t last_t_us_ = 0;
  Pose2D last_raw_;
  bool has_previous_ = false;  // the message taken before the last one
  int64_t previous_t_us_ = 0;
  Pose2D previous_raw_;
  Pose2D offset_;  // continuous = offset ⊕ raw
  int restarts_ = 0, outliers_ = 0, duplicates_ = 0;
  int64_t last_restart_us_ = -1;
  Restart last_restart_;
  bool candidate_ = false;  // the last message jumped: a restart if the next one agrees with it
  Pose2D candidate_raw_;
  int64_t candidate_t_us_ = 0, candidate_stamp_us_ = 0;
};

}  // namespace mbot::motion
