// What every live transport does at its edge when a sensor goes quiet: a watched channel silent for
// longer than `stale_s` stops the robot — the stack's velocity commands are replaced by zero and a
// zero command is due at `zero_rate_hz` (the firmware keeps the last command it got) — until every
// watched channel is heard again. Time is the caller's (a steady clock in seconds), so the policy is
// tested without a bus or a clock.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "mbot/msgs/events.hpp"

namespace mbot::msgs {

class SensorWatchdog {
 public:
  // Every watched channel counts as heard at `start_s`.
  SensorWatchdog(const std::vector<std::string>& watched, double stale_s, double start_s, double zero_rate_hz = 10.0);

  // A message arrived on `channel` at `now_s` (channels not watched are ignored).
  void Heard(const std::string& channel, double now_s);

  enum class Change { kNone, kHalted, kResumed };
  // Re-evaluates at `now_s`: kHalted when a watched channel has just gone silent (silent() names
  // them), kResumed when all are back.
  Change Check(double now_s);
  // While halted: true when a zero velocity command is due now (then it counts as sent).
  bool ZeroDue(double now_s);
  // The command to send in place of `command` (a velocity command on the command channel while
  // halted becomes zero, counted in held()); anything else passes unchanged.
  Event Filter(const Event& command, const std::string& command_channel);

  bool halted() const { return halted_; }
  const std::string& silent() const { return silent_; }  // "LIDAR, MBOT_ODOMETRY" when halted
  long long halts() const { return halts_; }
  long long held() const { return held_; }

 private:
  std::map<std::string, double> last_heard_s_;
  double stale_s_, zero_period_s_, last_zero_s_ = -1e300;
  bool halted_ = false;
  std::string silent_;
  long long halts_ = 0, held_ = 0;
};

}  // namespace mbot::msgs
