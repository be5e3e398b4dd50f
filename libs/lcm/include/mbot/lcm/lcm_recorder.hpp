// Records an event stream as an LCM log in the format lcm-logger writes, each event encoded as the
// current mbot_lcm_msgs message a robot publishes on its channel (lidar_t, pose2D_t,
// mbot_encoders_t, mbot_imu_t, twist2D_t, mbot_motor_pwm_t, mbot_motor_vel_t), so a simulated run
// replays through the same LCM log source as a real robot's log. The log is written to a temporary
// file and renamed on Close(): an interrupted run leaves the whole log up to that point, never half a
// record.
#pragma once

#include <map>
#include <memory>
#include <string>

#include "mbot/msgs/events.hpp"

namespace mbot::lcmio {

class LcmLogWriter;

class LcmRecorder {
 public:
  explicit LcmRecorder(const std::string& path);
  ~LcmRecorder();
  // Writes the event at its t_us; false (nothing written) for kinds with no LCM message (maps,
  // paths, statuses, calibration samples).
  bool Record(const msgs::Event& event);
  void Close();
  long long recorded() const { return recorded_; }
  // Events left out, by channel.
  const std::map<std::string, long long>& skipped() const { return skipped_; }

 private:
  std::unique_ptr<LcmLogWriter> writer_;
  long long recorded_ = 0;
  std::map<std::string, long long> skipped_;
};

}  // namespace mbot::lcmio
