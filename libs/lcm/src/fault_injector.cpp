#include "mbot/lcm/fault_injector.hpp"

namespace mbot::lcmio {

FaultInjector::FaultInjector(const FaultOptions& options)
    : o_(options), rng_(options.seed), faulty_(options.channels.begin(), options.channels.end()) {}

bool FaultInjector::Silenced(const std::string& channel, double t_s) const {
  for (const FaultOptions::Silence& s : o_.silences) {
    if (s.channel == channel && t_s >= s.at_s && t_s < s.at_s + s.for_s) return true;
  }
  return false;
}

void FaultInjector::Receive(bool to_autonomy, const std::string& channel, std::vector<uint8_t> data, double t_s) {
  RelayChannelStats& st = stats_[channel];
  ++st.received;
  if (Silenced(channel, t_s)) {
    ++st.silenced;
    return;
  }
  Message p{t_s, order_++, to_autonomy, channel, std::move(data)};
  if (!faulty_.empty() && !faulty_.count(channel)) {
    queue_.push(std::move(p));
    return;
  }
  if (Chance() < o_.drop_rate) {
    ++st.dropped;
    return;
  }
  if (!p.data.empty() && Chance() < o_.corrupt_rate) {
    ++st.corrupted;
    const int n = 1 + static_cast<int>(rng_() % 4);
    for (int i = 0; i < n; ++i) p.data[rng_() % p.data.size()] = static_cast<uint8_t>(rng_());
  }
  p.due_s = t_s + (o_.delay_ms + o_.jitter_ms * Chance()) * 1e-3;
  // A held message goes out right after this one.
  auto h = held_.find(channel);
  std::optional<Message> release;
  if (h != held_.end()) {
    release = std::move(h->second);
    held_.erase(h);
  }
  if (!release && Chance() < o_.reorder_rate) {
    ++st.reordered;
    held_.emplace(channel, std::move(p));
    return;
  }
  const bool twice = Chance() < o_.duplicate_rate;
  const double due = p.due_s;
  if (twice) {
    ++st.duplicated;
    Message copy = p;
    copy.order = order_++;
    queue_.push(std::move(copy));
  }
  queue_.push(std::move(p));
  if (release) {  // the held message goes out right after this one: the two swapped places
    release->due_s = due;
    release->order = order_++;
    queue_.push(std::move(*release));
  }
}

std::vector<FaultInjector::Message> FaultInjector::TakeDue(double t_s) {
  std::vector<Message> out;
  while (!queue_.empty() && queue_.top().due_s <= t_s) {
    out.push_back(queue_.top());
    ++stats_[out.back().channel].relayed;
    queue_.pop();
  }
  return out;
}

std::optional<double> FaultInjector::next_due_s() const {
  if (queue_.empty()) return std::nullopt;
  return queue_.top().due_s;
}

}  // namespace mbot::lcmio
