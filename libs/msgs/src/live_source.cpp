#include "mbot/msgs/live_source.hpp"

#include <algorithm>
#include <sstream>

#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"

namespace mbot::msgs {

namespace {

std::string Fixed(double v, int digits) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

}  // namespace

int64_t WallClockUs() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

LiveSourceOptions ParseLiveSourceOptions(config::Section& s, const std::string& prefix, LiveSourceOptions o) {
  const auto doc = [&prefix](const char* text) { return prefix + ": " + text; };
  o.channels = s.GetList("channels", o.channels, doc("channels to subscribe to"));
  o.duration_s = s.GetDouble("duration_s", o.duration_s, doc("the run ends after this long (0: never) [s]"), 0.0, 1e7);
  o.end_after_silence_s =
      s.GetDouble("end_after_silence_s", o.end_after_silence_s,
                  doc("the run ends when no message arrived for this long (0: never) [s]"), 0.0, 1e7);
  o.stale_sensor_s = s.GetDouble("stale_sensor_s", o.stale_sensor_s,
                                 doc("a watched channel silent this long stops the robot [s]"), 0.01, 1e4);
  o.watched = s.GetList("watched_channels", o.watched, doc("channels whose silence stops the robot"));
  o.command_channel = s.GetString("command_channel", o.command_channel, doc("velocity commands go out here"));
  o.report_every_s = s.GetDouble("report_every_s", o.report_every_s,
                                 doc("log the loop rate and latency this often (0: never) [s]"), 0.0, 1e6);
  return o;
}

LiveSource::LiveSource(std::unique_ptr<LiveLink> link, LiveSourceOptions options, std::string format)
    : link_(std::move(link)),
      o_(std::move(options)),
      format_(std::move(format)),
      watchdog_(o_.watched, o_.stale_sensor_s, 0.0, kZeroRateHz) {
  start_ = last_message_ = last_report_ = Clock::now();
  for (const std::string& c : o_.channels) channels_[c] = link_->Describe(c);
  mbot::log::Info(link_->name() + ": listening on " + link_->where() + " to " + std::to_string(o_.channels.size()) +
                  " channels");
}

std::optional<Event> LiveSource::Next() {
  for (;;) {
    const Clock::time_point now = Clock::now();  // intervals on the steady clock: a wall-clock step cannot fool them
    if (o_.duration_s > 0 && now - start_ >= Seconds(o_.duration_s)) {
      Report(now, true);
      return std::nullopt;
    }
    if (o_.end_after_silence_s > 0 && now - last_message_ >= Seconds(o_.end_after_silence_s)) {
      mbot::log::Info(link_->name() + ": nothing arrived for " + Fixed(o_.end_after_silence_s, 1) +
                      " s: ending the run");
      Report(now, true);
      return std::nullopt;
    }
    // Take what is waiting first, so a newer scan behind the queue is seen before an older one is
    // processed.
    got_.clear();
    link_->Poll(queue_.empty() ? 50 : 0, &got_);
    diagnostics_.rejected_messages = link_->rejected_total();
    for (Event& e : got_) {
      last_message_ = Clock::now();
      watchdog_.Heard(e.channel, SecondsSinceStart(last_message_));
      auto it = channels_.find(e.channel);
      if (it == channels_.end()) it = channels_.emplace(e.channel, link_->Describe(e.channel)).first;
      it->second.kind = e.kind;
      queue_.push_back(std::move(e));
    }
    Watchdog(Clock::now());
    Report(Clock::now(), false);
    if (queue_.empty()) {
      const int64_t t = WallClockUs();
      return Event{t, t, "LIVE_TICK", EventKind::kOther, {}};  // lets the pipeline check its stop flag
    }
    Event ev = std::move(queue_.front());
    queue_.pop_front();
    // A scan overtaken by a newer one is stale: drop it rather than fall behind.
    if (ev.kind == EventKind::kLidar &&
        std::any_of(queue_.begin(), queue_.end(), [](const Event& e) { return e.kind == EventKind::kLidar; })) {
      ++dropped_scans_;
      continue;
    }
    latency_ms_.push_back((WallClockUs() - ev.t_us) * 1e-3);
    if (latency_ms_.size() >= kMaxLatencySamples) Report(Clock::now(), true);
    ++delivered_;
    return ev;
  }
}

void LiveSource::Watchdog(Clock::time_point now) {
  const double t_s = SecondsSinceStart(now);
  switch (watchdog_.Check(t_s)) {
    case SensorWatchdog::Change::kHalted:
      mbot::log::Warn(link_->name() + ": no " + watchdog_.silent() + " for " + Fixed(o_.stale_sensor_s, 1) +
                      " s: robot stopped (zero velocity on " + o_.command_channel + ") until it is back");
      break;
    case SensorWatchdog::Change::kResumed:
      mbot::log::Info(link_->name() + ": sensors back: commands pass again");
      break;
    case SensorWatchdog::Change::kNone: break;
  }
  if (watchdog_.ZeroDue(t_s)) {
    const int64_t t = WallClockUs();
    link_->Publish(Event{t, t, o_.command_channel, EventKind::kMotorCommand, MotorCommand::Velocity(0, 0)});
  }
}

void LiveSource::Send(const Event& event) {
  Event out = watchdog_.Filter(event, o_.command_channel);
  if (out.stamp_us == 0) out.stamp_us = WallClockUs();
  link_->Publish(out);
}

void LiveSource::Report(Clock::time_point now, bool force) {
  const bool due = o_.report_every_s > 0 && now - last_report_ >= Seconds(o_.report_every_s);
  if (!force && !due) return;
  const double span_s = std::chrono::duration<double>(now - last_report_).count();
  last_rate_hz_ = span_s > 0 ? (delivered_ - delivered_at_report_) / span_s : 0.0;
  if (!latency_ms_.empty()) {
    std::sort(latency_ms_.begin(), latency_ms_.end());
    last_latency_median_ms_ = latency_ms_[latency_ms_.size() / 2];
    last_latency_max_ms_ = latency_ms_.back();
  }
  if (o_.report_every_s > 0) {
    mbot::log::Info(link_->name() + ": " + Fixed(last_rate_hz_, 1) +
                    " messages/s processed, arrival-to-processing latency median " + Fixed(last_latency_median_ms_, 2) +
                    " ms, max " + Fixed(last_latency_max_ms_, 2) + " ms; " + std::to_string(link_->rejected_total()) +
                    " rejected, " + std::to_string(dropped_scans_) + " stale scans dropped, " +
                    std::to_string(watchdog_.halts()) + " sensor stops");
  }
  latency_ms_.clear();
  delivered_at_report_ = delivered_;
  last_report_ = now;
}

double LiveSource::Progress() const {
  if (o_.duration_s <= 0) return 0.0;
  return std::min(1.0, std::chrono::duration<double>(Clock::now() - start_).count() / o_.duration_s);
}

std::vector<std::pair<std::string, std::string>> LiveSource::Details() const {
  std::vector<std::pair<std::string, std::string>> d = {
      {"url", link_->where()},
      {"messages processed", std::to_string(delivered_)},
      {"rejected (malformed or unknown)", std::to_string(link_->rejected_total())},
      {"stale scans dropped", std::to_string(dropped_scans_)},
      {"sensor stops", std::to_string(watchdog_.halts())},
      {"commands held back", std::to_string(watchdog_.held())},
      {"loop rate", Fixed(last_rate_hz_, 1) + " messages/s"},
      {"latency",
       "median " + Fixed(last_latency_median_ms_, 2) + " ms, max " + Fixed(last_latency_max_ms_, 2) + " ms"}};
  for (auto& kv : link_->Details()) d.push_back(std::move(kv));
  return d;
}

}  // namespace mbot::msgs
