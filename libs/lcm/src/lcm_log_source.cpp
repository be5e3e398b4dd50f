#include "lcm_log_source.hpp"

#include <algorithm>
#include <cstdio>

#include "lcm_messages.hpp"
#include "mbot/common/log.hpp"

namespace mbot::lcmio {

using namespace msgs;  // the event vocabulary

LcmLogSource::LcmLogSource(const SourceOptions& options)
    : options_(options), log_(ExtraOr<LcmLogOptions>(options)), reader_(options.path) {}

double LcmLogSource::Progress() const {
  return reader_.size() > 0 ? double(reader_.position()) / double(reader_.size()) : 1.0;
}

std::optional<Event> LcmLogSource::ReadOne() {
  while (auto rec = reader_.Next()) {
    diagnostics_.resyncs = reader_.resyncs();
    diagnostics_.skipped_bytes = reader_.skipped_bytes();
    const int64_t fp = lcm_adapter::Fingerprint(rec->data.data(), rec->data.size());
    const lcm_adapter::TypeInfo* type = lcm_adapter::LookUp(fp);
    auto& info = channels_[rec->channel];
    if (!type && (rec->channel == "LCM_SELF_TEST" || rec->channel == "LCM_TUNNEL_INTROSPECT")) {
      info.type = "lcm-logger internal";  // written by LCM itself, not a message type
      info.kind = EventKind::kOther;
      continue;
    }
    if (!type) {
      ++diagnostics_.unknown_messages;
      info.decoded = false;
      char hex[24];
      std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(fp));
      info.type = std::string("unknown (fingerprint ") + hex + ")";
      if (warned_unknown_.insert(rec->channel).second) {
        mbot::log::Warn(options_.path + ": channel " + rec->channel + " has an unknown message type (fingerprint " +
                        hex + "); its messages are skipped");
      }
      continue;
    }
    info.type = type->type;
    info.generation = type->generation;
    Event ev;
    ev.t_us = rec->timestamp_us;
    ev.channel = rec->channel;
    std::string error;
    if (!lcm_adapter::Decode(rec->channel, rec->data.data(), rec->data.size(), options_.roles, &ev, &error)) {
      ++diagnostics_.rejected_messages;
      mbot::log::Warn(options_.path + ": rejected message on channel " + rec->channel + " (event " +
                      std::to_string(rec->event_number) + ", byte " + std::to_string(rec->file_offset) + "): " + error);
      continue;
    }
    // The logger's stamp is µs since the epoch: below zero or beyond 2100 it is garbage, and the
    // record is rejected (as lcm_live rejects such a utime on the bus). A message's own utime is
    // garbage in some real logs (the 2017 staff SLAM_MAP): the message is kept, on the log's time.
    if (!IsPlausibleTimeUs(rec->timestamp_us)) {
      ++diagnostics_.rejected_messages;
      mbot::log::Warn(options_.path + ": rejected message on channel " + rec->channel + " (event " +
                      std::to_string(rec->event_number) + ", byte " + std::to_string(rec->file_offset) +
                      "): absurd log timestamp " + std::to_string(rec->timestamp_us) + " us");
      continue;
    }
    if (!IsPlausibleTimeUs(ev.stamp_us)) {
      mbot::log::WarnOnce(options_.path + ":utime:" + rec->channel,
                          options_.path + ": channel " + rec->channel + " has absurd utime values (" +
                              std::to_string(ev.stamp_us) + " us at event " + std::to_string(rec->event_number) +
                              "); those messages take the log's time");
      ev.stamp_us = rec->timestamp_us;
    }
    info.kind = ev.kind;
    if (ev.kind == EventKind::kGroundTruth &&
        std::find(options_.roles.rezero_ground_truth.begin(), options_.roles.rezero_ground_truth.end(), rec->channel) !=
            options_.roles.rezero_ground_truth.end()) {
      auto& pose = std::get<msgs::Pose2D>(ev.payload);
      auto [it, first] = rezero_origin_.emplace(rec->channel, pose);
      // Subtract the first pose and rotate by -θ0, so ground truth starts at the origin like odometry.
      pose = it->second.Inverse().Compose(pose);
      (void)first;
    }
    return ev;
  }
  diagnostics_.resyncs = reader_.resyncs();
  diagnostics_.skipped_bytes = reader_.skipped_bytes();
  diagnostics_.truncated_tail = reader_.truncated();
  return std::nullopt;
}

std::optional<Event> LcmLogSource::Next() {
  // Fill until the oldest pending event is older than the newest by more than the window.
  while (!eof_ && (pending_.empty() || pending_.back().t_us - pending_.front().t_us <= log_.reorder_window_us)) {
    std::optional<Event> ev = ReadOne();
    if (!ev) {
      eof_ = true;
      break;
    }
    auto pos = std::upper_bound(pending_.begin(), pending_.end(), ev->t_us,
                                [](int64_t t, const Event& e) { return t < e.t_us; });
    pending_.insert(pos, std::move(*ev));
  }
  if (pending_.empty()) return std::nullopt;
  Event out = std::move(pending_.front());
  pending_.pop_front();
  if (out.t_us < last_emitted_us_) {
    ++diagnostics_.out_of_order;
    mbot::log::WarnOnce(options_.path + ":order", options_.path + ": event on " + out.channel + " is " +
                                                      std::to_string(last_emitted_us_ - out.t_us) +
                                                      " us older than one already emitted (beyond the reorder window)");
  }
  last_emitted_us_ = std::max(last_emitted_us_, out.t_us);
  return out;
}

}  // namespace mbot::lcmio
