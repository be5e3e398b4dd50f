#include "lcm_live_source.hpp"

#include <algorithm>
#include <sstream>

#include "mbot/common/log.hpp"

namespace mbot::drivers {
namespace {

std::string Fixed(double v, int digits) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

}  // namespace

LcmLiveSource::LcmLiveSource(const SourceOptions& options)
    : o_(options.live), node_(options.path, options.live.channels, options.roles) {
  start_us_ = last_message_us_ = last_report_us_ = WallClockUs();
  for (const std::string& c : o_.watched) last_seen_us_[c] = start_us_;
  for (const std::string& c : o_.channels) channels_[c] = ChannelInfo{"", "2023+", EventKind::kOther, true};
  mbot::log::Info("lcm: listening on " + options.path + " to " + std::to_string(o_.channels.size()) + " channels");
}

std::optional<Event> LcmLiveSource::Next() {
  for (;;) {
    const int64_t now = WallClockUs();
    if (o_.duration_s > 0 && now - start_us_ >= static_cast<int64_t>(o_.duration_s * 1e6)) return std::nullopt;
    if (o_.end_after_silence_s > 0 && now - last_message_us_ >= static_cast<int64_t>(o_.end_after_silence_s * 1e6)) {
      mbot::log::Info("lcm: nothing arrived for " + Fixed(o_.end_after_silence_s, 1) + " s: ending the run");
      return std::nullopt;
    }
    Watchdog(now);
    Report(now, false);
    if (!queue_.empty()) {
      Event ev = std::move(queue_.front());
      queue_.pop_front();
      // A scan overtaken by a newer one still waiting is stale: drop it rather than fall behind.
      if (ev.kind == EventKind::kLidar &&
          std::any_of(queue_.begin(), queue_.end(), [](const Event& e) { return e.kind == EventKind::kLidar; })) {
        ++dropped_scans_;
        continue;
      }
      latency_ms_.push_back((now - ev.t_us) * 1e-3);
      ++delivered_;
      return ev;
    }
    std::vector<Event> got;
    node_.Poll(50, &got);
    diagnostics_.rejected_messages = node_.rejected_total();
    if (got.empty()) return Event{now, now, "LIVE_TICK", EventKind::kOther, {}};
    for (Event& e : got) {
      last_message_us_ = e.t_us;
      if (last_seen_us_.count(e.channel)) last_seen_us_[e.channel] = e.t_us;
      channels_[e.channel].kind = e.kind;
      queue_.push_back(std::move(e));
    }
  }
}

void LcmLiveSource::Watchdog(int64_t now_us) {
  std::string silent;
  for (const auto& [channel, seen] : last_seen_us_) {
    if (now_us - seen > static_cast<int64_t>(o_.stale_sensor_s * 1e6)) silent += (silent.empty() ? "" : ", ") + channel;
  }
  if (!silent.empty() && !halted_) {
    halted_ = true;
    ++halts_;
    mbot::log::Warn("lcm: no " + silent + " for " + Fixed(o_.stale_sensor_s, 1) + " s: robot stopped (zero velocity on " +
                    o_.command_channel + ") until it is back");
  } else if (silent.empty() && halted_) {
    halted_ = false;
    mbot::log::Info("lcm: sensors back: commands pass again");
  }
  if (halted_) {
    const int64_t t = now_us;
    node_.Publish(Event{t, t, o_.command_channel, EventKind::kMotorCommand, MotorCommand{MotorCommand::Kind::kVelocity, 0, 0}});
  }
}

void LcmLiveSource::Send(const Event& event) {
  Event out = event;
  out.stamp_us = WallClockUs();  // outgoing messages carry the time they were sent
  if (event.kind == EventKind::kMotorCommand && event.channel == o_.command_channel && halted_) {
    ++held_commands_;
    out.payload = MotorCommand{MotorCommand::Kind::kVelocity, 0, 0};
  }
  node_.Publish(out);
}

void LcmLiveSource::Report(int64_t now_us, bool force) {
  if (!force && (o_.report_every_s <= 0 || now_us - last_report_us_ < static_cast<int64_t>(o_.report_every_s * 1e6))) return;
  const double span_s = (now_us - last_report_us_) * 1e-6;
  last_rate_hz_ = span_s > 0 ? (delivered_ - delivered_at_report_) / span_s : 0.0;
  if (!latency_ms_.empty()) {
    std::sort(latency_ms_.begin(), latency_ms_.end());
    last_latency_median_ms_ = latency_ms_[latency_ms_.size() / 2];
    last_latency_max_ms_ = latency_ms_.back();
  }
  mbot::log::Info("lcm: " + Fixed(last_rate_hz_, 1) + " messages/s processed, arrival-to-processing latency median " +
                  Fixed(last_latency_median_ms_, 2) + " ms, max " + Fixed(last_latency_max_ms_, 2) + " ms; " +
                  std::to_string(node_.rejected_total()) + " rejected, " + std::to_string(dropped_scans_) +
                  " stale scans dropped, " + std::to_string(halts_) + " sensor stops");
  latency_ms_.clear();
  delivered_at_report_ = delivered_;
  last_report_us_ = now_us;
}

double LcmLiveSource::Progress() const {
  if (o_.duration_s <= 0) return 0.0;
  return std::min(1.0, (WallClockUs() - start_us_) * 1e-6 / o_.duration_s);
}

std::vector<std::pair<std::string, std::string>> LcmLiveSource::Details() const {
  std::vector<std::pair<std::string, std::string>> d = {
      {"url", node_.url()},
      {"messages processed", std::to_string(delivered_)},
      {"rejected (malformed or unknown)", std::to_string(node_.rejected_total())},
      {"stale scans dropped", std::to_string(dropped_scans_)},
      {"sensor stops", std::to_string(halts_)},
      {"commands held back", std::to_string(held_commands_)},
      {"loop rate", Fixed(last_rate_hz_, 1) + " messages/s"},
      {"latency", "median " + Fixed(last_latency_median_ms_, 2) + " ms, max " + Fixed(last_latency_max_ms_, 2) + " ms"}};
  for (const auto& [channel, s] : node_.stats()) {
    if (s.rejected + s.unknown > 0) d.push_back({"rejected on " + channel, std::to_string(s.rejected + s.unknown) + " (" + s.last_error + ")"});
  }
  return d;
}

}  // namespace mbot::drivers
