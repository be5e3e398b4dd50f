// `[source] type = lcm_live`: the autonomy's side of a robot on the LCM bus, as a Source (the
// robot's sensor messages, validated at the edge) and a Sink (velocity commands, SLAM pose and map,
// paths and statuses published as the botlab's messages). Time is the wall clock: t_us is when a
// message arrived. A scan that a newer one overtook in the queue is dropped, not processed late. A
// watched sensor (LIDAR, MBOT_ODOMETRY) silent for stale_sensor_s is reported and the robot stopped:
// zero velocity is published and the stack's commands are held back until it is back.
#pragma once

#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "mbot/drivers/lcm_live.hpp"
#include "mbot/drivers/sink.hpp"
#include "mbot/drivers/source.hpp"
#include "mbot/drivers/source_options.hpp"

namespace mbot::drivers {

class LcmLiveSource : public Source, public Sink {
 public:
  explicit LcmLiveSource(const SourceOptions& options);

  // The next message, or a heartbeat (kOther on channel LIVE_TICK) after 50 ms without one, so the
  // pipeline keeps checking its stop flag; nullopt at duration_s or after end_after_silence_s.
  std::optional<Event> Next() override;
  double Progress() const override;
  std::string Format() const override { return "live LCM"; }
  std::vector<std::pair<std::string, std::string>> Details() const override;
  void Send(const Event& event) override;

 private:
  void Watchdog(int64_t now_us);
  void Report(int64_t now_us, bool force);

  LiveSourceOptions o_;
  LcmNode node_;
  std::deque<Event> queue_;
  int64_t start_us_ = 0, last_message_us_ = 0, last_report_us_ = 0;
  std::map<std::string, int64_t> last_seen_us_;  // watched channels
  bool halted_ = false;                          // a watched sensor is silent: commands held back
  long long halts_ = 0, held_commands_ = 0, dropped_scans_ = 0, delivered_ = 0;
  long long delivered_at_report_ = 0;
  std::vector<double> latency_ms_;  // arrival to delivery, since the last report
  double last_rate_hz_ = 0, last_latency_median_ms_ = 0, last_latency_max_ms_ = 0;
};

}  // namespace mbot::drivers
