// The autonomy's side of a live robot, whatever the transport (LCM, ROS 2 over DDS): a Source of the
// robot's sensor messages, validated at the transport's edge, and a Sink for the stack's commands
// and outputs. Time is the wall clock: t_us is when the transport received a message. Whatever is
// waiting is taken before the next event is delivered, and a scan a newer one overtook is dropped,
// not processed late. A watched sensor silent for stale_sensor_s is reported and the robot stopped:
// zero velocity goes out at 10 Hz and the stack's commands are held back until it is back. The
// watchdog runs between events, so a stage that blocks for long also delays it.
#pragma once

#include <chrono>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "mbot/msgs/sensor_watchdog.hpp"
#include "mbot/msgs/sink.hpp"
#include "mbot/msgs/source.hpp"

namespace mbot::config {
class Section;
}

namespace mbot::msgs {

// [source] keys every live transport shares.
struct LiveSourceOptions {
  // The robot's channels the autonomy listens to (pipeline topic names; the transport maps them).
  std::vector<std::string> channels = {topics::kLidar,    topics::kOdometry, topics::kEncoders,   topics::kImu,
                                       topics::kTimesync, topics::kPath,     topics::kSystemReset};
  double duration_s = 0.0;           // 0: until Ctrl-C or a stage ends the run
  double end_after_silence_s = 0.0;  // > 0: the run ends when nothing arrived for this long
  // A watched channel silent this long is reported and the robot stopped (zero velocity published,
  // commands held back) until it is back.
  double stale_sensor_s = 1.0;
  std::vector<std::string> watched = {topics::kLidar, topics::kOdometry};
  std::string command_channel = topics::kVelocityCommand;
  double report_every_s = 10.0;  // a line with the loop rate and latency this often (0: never)
};
// Reads them from [source]; `prefix` names the type in the documentation ("lcm_live").
LiveSourceOptions ParseLiveSourceOptions(config::Section& section, const std::string& prefix,
                                         LiveSourceOptions defaults = {});

// What a transport gives a LiveSource: its messages as validated events, and a way out.
class LiveLink {
 public:
  virtual ~LiveLink() = default;
  // Waits up to timeout_ms for messages and appends what arrived (t_us: when it was received).
  virtual void Poll(int timeout_ms, std::vector<Event>* out) = 0;
  // Sends one event as the transport's message; false when it has none or the send failed.
  virtual bool Publish(const Event& event) = 0;
  // Messages refused at the edge (malformed, unknown type, absurd time) so far.
  virtual long long rejected_total() const = 0;
  // "lcm", "ros2": the prefix of its log lines.
  virtual std::string name() const = 0;
  // Where it listens ("udpm://…", "DDS domain 0").
  virtual std::string where() const = 0;
  // What it learnt about a channel once a message arrived there.
  virtual ChannelInfo Describe(const std::string& channel) const = 0;
  // Per-channel facts for the run's summary (rejections with their reason, echoes).
  virtual std::vector<std::pair<std::string, std::string>> Details() const { return {}; }
};

class LiveSource : public Source, public Sink {
 public:
  LiveSource(std::unique_ptr<LiveLink> link, LiveSourceOptions options, std::string format);
  Sink* sink() override { return this; }

  // The next message, or a heartbeat (kOther on channel LIVE_TICK) after 50 ms without one, so the
  // pipeline keeps checking its stop flag; nullopt at duration_s or after end_after_silence_s.
  std::optional<Event> Next() override;
  double Progress() const override;
  std::string Format() const override { return format_; }
  std::vector<std::pair<std::string, std::string>> Details() const override;
  void Send(const Event& event) override;
  LiveLink& link() { return *link_; }

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

  std::unique_ptr<LiveLink> link_;
  LiveSourceOptions o_;
  std::string format_;
  std::deque<Event> queue_;
  std::vector<Event> got_;  // reused between polls
  Clock::time_point start_, last_message_, last_report_;
  SensorWatchdog watchdog_;  // a watched sensor silent: commands held back, zero velocity out
  long long dropped_scans_ = 0, delivered_ = 0;
  long long delivered_at_report_ = 0;
  std::vector<double> latency_ms_;  // arrival (the transport's receive) to delivery, since the last report
  double last_rate_hz_ = 0, last_latency_median_ms_ = 0, last_latency_max_ms_ = 0;
};

// Microseconds since the epoch (what live events are stamped with).
int64_t WallClockUs();

}  // namespace mbot::msgs
