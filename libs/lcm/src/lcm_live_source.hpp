// `[source] type = lcm_live`: the autonomy's side of a robot on the LCM bus, as a Source (the
// robot's sensor messages, validated at the edge) and a Sink (velocity commands, SLAM pose, map and
// particles, paths and statuses published as the botlab's messages). Time is the wall clock: t_us
// is when LCM's receive thread got a message. Whatever is waiting is taken before the next event is
// delivered, and a scan a newer one overtook is dropped, not processed late. A watched sensor
// (LIDAR, MBOT_ODOMETRY) silent for stale_sensor_s is reported and the robot stopped: zero velocity
// goes out at 10 Hz and the stack's commands are held back until it is back. The watchdog runs
// between events, so a stage that blocks for long also delays it (a watchdog thread of its own
// would close that gap).
#pragma once

#include <chrono>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "mbot/lcm/lcm_live.hpp"
#include "mbot/msgs/sensor_watchdog.hpp"
#include "mbot/msgs/sink.hpp"
#include "mbot/msgs/source.hpp"
#include "mbot/lcm/lcm_sources.hpp"

namespace mbot::lcmio {

using namespace msgs;  // the event vocabulary

class LcmLiveSource : public Source, public Sink {
 public:
  Sink* sink() override { return this; }
  explicit LcmLiveSource(const SourceOptions& options);

  // The next message, or a heartbeat (kOther on channel LIVE_TICK) after 50 ms without one, so the
  // pipeline keeps checking its stop flag; nullopt at duration_s or after end_after_silence_s.
  std::optional<Event> Next() override;
  double Progress() const override;
  std::string Format() const override { return "live LCM"; }
  std::vector<std::pair<std::string, std::string>> Details() const override;
  void Send(const Event& event) override;

 private:
  using Clock = std::chrono::steady_clock;
  static Clock::duration Seconds(double s) {
    return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
  }
  static constexpr double kZeroRateHz = 10.0;           // zero velocity while halted
  static constexpr size_t kMaxLatencySamples = 100000;  // a report (and a fresh window) at the latest then

  void Watchdog(Clock::time_point now);
  double SecondsSinceStart(Clock::time_point t) const { return std::chrono::duration<double>(t - start_).count(); }
  void Report(Clock::time_point now, bool force);

  LiveSourceOptions o_;
  LcmNode node_;
  std::deque<Event> queue_;
  Clock::time_point start_, last_message_, last_report_;
  SensorWatchdog watchdog_;  // a watched sensor silent: commands held back, zero velocity out
  long long dropped_scans_ = 0, delivered_ = 0;
  long long delivered_at_report_ = 0;
  std::vector<double> latency_ms_;  // arrival (LCM's receive thread) to delivery, since the last report
  double last_rate_hz_ = 0, last_latency_median_ms_ = 0, last_latency_max_ms_ = 0;
};

}  // namespace mbot::lcmio
