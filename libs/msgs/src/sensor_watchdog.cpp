#include "mbot/msgs/sensor_watchdog.hpp"

namespace mbot::msgs {

SensorWatchdog::SensorWatchdog(const std::vector<std::string>& watched, double stale_s, double start_s,
                               double zero_rate_hz)
    : stale_s_(stale_s), zero_period_s_(zero_rate_hz > 0 ? 1.0 / zero_rate_hz : 1e300) {
  for (const std::string& c : watched) last_heard_s_[c] = start_s;
}

void SensorWatchdog::Heard(const std::string& channel, double now_s) {
  if (auto it = last_heard_s_.find(channel); it != last_heard_s_.end()) it->second = now_s;
}

SensorWatchdog::Change SensorWatchdog::Check(double now_s) {
  std::string silent;
  for (const auto& [channel, heard] : last_heard_s_) {
    if (now_s - heard > stale_s_) silent += (silent.empty() ? "" : ", ") + channel;
  }
  if (!silent.empty() && !halted_) {
    halted_ = true;
    ++halts_;
    silent_ = silent;
    return Change::kHalted;
  }
  if (silent.empty() && halted_) {
    halted_ = false;
    silent_.clear();
    return Change::kResumed;
  }
  if (halted_) silent_ = silent;
  return Change::kNone;
}

bool SensorWatchdog::ZeroDue(double now_s) {
  if (!halted_ || now_s - last_zero_s_ < zero_period_s_) return false;
  last_zero_s_ = now_s;
  return true;
}

Event SensorWatchdog::Filter(const Event& command, const std::string& command_channel) {
  Event out = command;
  if (halted_ && command.kind == EventKind::kMotorCommand && command.channel == command_channel) {
    ++held_;
    out.payload = MotorCommand::Velocity(0, 0);
  }
  return out;
}

}  // namespace mbot::msgs
