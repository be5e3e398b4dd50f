#include "mbot/lcm/lcm_live.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <functional>
#include <lcm/lcm-cpp.hpp>
#include <stdexcept>
#include <thread>

#include "lcm_messages.hpp"
#include "mbot/common/log.hpp"

namespace mbot::lcmio {

using namespace msgs;  // the event vocabulary

std::string LcmChannelPattern(const std::string& channel) {
  std::string exact;
  for (const char ch : channel)
    exact += std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' ? std::string(1, ch) : std::string("\\") + ch;
  return exact;
}

struct LcmNode::Impl {
  lcm::LCM lcm;
  std::vector<Event>* sink = nullptr;  // where the handler puts decoded events during Poll
  LcmNode* node = nullptr;
  explicit Impl(const std::string& url) : lcm(url) {}

  void OnMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    LcmChannelStats& s = node->stats_[channel];
    ++s.received;
    const auto* data = static_cast<const uint8_t*>(rbuf->data);
    const size_t size = rbuf->data_size;
    // Our own message coming back (multicast loops back to the sender): not news.
    const size_t h = std::hash<std::string_view>()(std::string_view(reinterpret_cast<const char*>(data), size));
    if (node->RecentlyPublished(channel, h)) {
      ++s.own_echoes;
      return;
    }
    if (!lcm_adapter::LookUp(lcm_adapter::Fingerprint(data, size))) {
      ++s.unknown;
      s.last_error = "unknown fingerprint (or a packet shorter than one)";
      mbot::log::WarnOnce("lcm_live:unknown:" + channel,
                          "lcm: " + channel + ": message of an unknown type, skipped (counted)");
      return;
    }
    Event ev;
    std::string error;
    if (!lcm_adapter::Decode(channel, data, size, node->roles_, &ev, &error)) {
      ++s.rejected;
      s.last_error = error;
      mbot::log::WarnOnce("lcm_live:rejected:" + channel,
                          "lcm: " + channel + ": malformed message rejected (" + error + "); further ones are counted");
      return;
    }
    // utime is µs on the robot's clock (since boot, or the epoch once time-synced): below zero or
    // beyond 2100 it is garbage, whatever the payload says.
    if (!IsPlausibleTimeUs(ev.stamp_us)) {
      ++s.rejected;
      s.last_error = "absurd timestamp utime = " + std::to_string(ev.stamp_us);
      mbot::log::WarnOnce("lcm_live:time:" + channel,
                          "lcm: " + channel + ": " + s.last_error + "; rejected (further ones are counted)");
      return;
    }
    ev.channel = channel;
    ev.t_us = rbuf->recv_utime;  // when the receive thread got it (what lcm-logger stamps)
    if (sink) sink->push_back(std::move(ev));
  }
};

LcmNode::LcmNode(const std::string& url, const std::vector<std::string>& channels, const ChannelRoles& roles)
    : impl_(std::make_unique<Impl>(url)), url_(url), roles_(roles) {
  if (!impl_->lcm.good()) throw std::runtime_error("lcm: cannot open '" + url + "'");
  impl_->node = this;
  for (const std::string& c : channels) {
    if (!impl_->lcm.subscribe(LcmChannelPattern(c), &Impl::OnMessage, impl_.get())) {
      throw std::runtime_error("lcm: cannot subscribe to '" + c + "' on '" + url + "'");
    }
    stats_[c];
    subscribed_.insert(c);
  }
}

LcmNode::~LcmNode() = default;

void LcmNode::Poll(int timeout_ms, std::vector<Event>* out) {
  impl_->sink = out;
  // handleTimeout: > 0 handled one message, 0 timed out, < 0 error.
  int r = impl_->lcm.handleTimeout(timeout_ms);
  while (r > 0) r = impl_->lcm.handleTimeout(0);
  impl_->sink = nullptr;
  if (r < 0) {
    mbot::log::WarnOnce("lcm_live:handle", "lcm: receiving on " + url_ + " failed");
    std::this_thread::sleep_for(std::chrono::milliseconds(timeout_ms));  // do not spin on a broken socket
  }
}

bool LcmNode::Publish(const Event& event) {
  std::vector<uint8_t> data;
  if (!lcm_adapter::Encode(event, &data)) return false;
  return PublishRaw(event.channel, data);
}

bool LcmNode::PublishRaw(const std::string& channel, const std::vector<uint8_t>& data) {
  if (impl_->lcm.publish(channel, data.data(), static_cast<unsigned>(data.size())) != 0) {
    mbot::log::WarnOnce("lcm_live:publish:" + channel, "lcm: publishing " + channel + " on " + url_ + " failed");
    return false;
  }
  ++stats_[channel].published;
  if (subscribed(channel)) {  // remember it, to know its echo
    const size_t h =
        std::hash<std::string_view>()(std::string_view(reinterpret_cast<const char*>(data.data()), data.size()));
    auto& recent = recent_[channel];
    recent.push_back(h);
    if (recent.size() > kRecentPerChannel) recent.pop_front();
  }
  return true;
}

bool LcmNode::RecentlyPublished(const std::string& channel, size_t hash) {
  auto it = recent_.find(channel);
  if (it == recent_.end()) return false;
  auto pos = std::find(it->second.begin(), it->second.end(), hash);
  if (pos == it->second.end()) return false;
  it->second.erase(pos);
  return true;
}

std::vector<uint8_t> EncodeEvent(const Event& event) {
  std::vector<uint8_t> data;
  lcm_adapter::Encode(event, &data);
  return data;
}

bool LcmNode::subscribed(const std::string& channel) const { return subscribed_.count(channel) > 0; }

long long LcmNode::rejected_total() const {
  long long n = 0;
  for (const auto& [c, s] : stats_) n += s.rejected + s.unknown;
  return n;
}

}  // namespace mbot::lcmio
