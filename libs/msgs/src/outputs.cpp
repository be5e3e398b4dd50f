#include "mbot/msgs/outputs.hpp"

#include <chrono>
#include <cmath>
#include <stdexcept>

#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"

namespace mbot::msgs {

OutputOptions ParseOutputOptions(config::Section& s, const OutputType& type) {
  OutputOptions o;
  for (const std::string& c : s.GetList("channels", {}, "send only these channels (empty: every channel)")) {
    o.channels.insert(c);
  }
  std::vector<std::string> default_rates;
  for (size_t pos = 0; pos < type.default_max_rate_hz.size();) {
    size_t comma = type.default_max_rate_hz.find(',', pos);
    if (comma == std::string::npos) comma = type.default_max_rate_hz.size();
    std::string item = type.default_max_rate_hz.substr(pos, comma - pos);
    item.erase(0, item.find_first_not_of(' '));
    item.erase(item.find_last_not_of(' ') + 1);
    if (!item.empty()) default_rates.push_back(item);
    pos = comma + 1;
  }
  for (const std::string& item : s.GetList(
           "max_rate_hz", default_rates, "kind:rate pairs, e.g. 'map:1, particles:5': at most that many per second")) {
    const size_t colon = item.find(':');
    const std::optional<EventKind> kind = KindFromKey(item.substr(0, colon));
    if (colon == std::string::npos || !kind) {
      s.Fail("max_rate_hz", "'" + item + "' is not kind:rate (kinds: lidar, odometry, map, path, particles, ...)");
    }
    double hz = 0.0;
    try {
      size_t used = 0;
      hz = std::stod(item.substr(colon + 1), &used);
      if (used != item.size() - colon - 1) throw std::invalid_argument("trailing");
    } catch (const std::exception&) {
      s.Fail("max_rate_hz", "'" + item + "': the rate is not a number");
    }
    if (!(hz > 0.0 && hz <= 1e6)) s.Fail("max_rate_hz", "'" + item + "': the rate must be in (0, 1e6] Hz");
    o.max_rate_hz[*kind] = hz;
  }
  o.queue_per_kind = static_cast<size_t>(
      s.GetInt("queue_per_kind", static_cast<long long>(o.queue_per_kind),
               "events of one kind that may wait for the output; then the oldest is dropped", 1, 1 << 20));
  o.wait_when_full =
      s.GetChoice("when_full", type.wait_when_full ? "wait" : "drop_oldest", {"drop_oldest", "wait"},
                  "a full queue drops the kind's oldest event, or waits for room (stalls the run)") == "wait";
  return o;
}

long long OutputCounts::dropped_total() const {
  long long n = 0;
  for (const auto& [kind, count] : dropped) n += count;
  return n;
}

std::string OutputCounts::ToString() const {
  std::string s = std::to_string(sent) + " sent";
  if (const long long d = dropped_total()) {
    std::string by;
    for (const auto& [kind, count] : dropped) {
      by += (by.empty() ? "" : ", ") + std::string(msgs::ToString(kind)) + " " + std::to_string(count);
    }
    s += ", " + std::to_string(d) + " dropped (" + by + ")";
  }
  if (rate_limited) s += ", " + std::to_string(rate_limited) + " rate-limited";
  if (!error.empty()) s += "; failed: " + error;
  return s;
}

OutputRunner::OutputRunner(std::string name, std::unique_ptr<Output> output, OutputOptions options)
    : name_(std::move(name)), output_(std::move(output)), options_(std::move(options)) {}

OutputRunner::~OutputRunner() { StopThread(); }

void OutputRunner::StopThread() {
  if (!thread_.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closing_ = true;
  }
  ready_.notify_all();
  room_.notify_all();
  thread_.join();  // the thread sends what is still queued first
}

void OutputRunner::Open(const RunContext& context) {
  output_->Open(context);
  thread_ = std::thread([this] { Run(); });
}

void OutputRunner::Offer(const Event& e) {
  if (!options_.channels.empty() && !options_.channels.count(e.channel)) return;
  const int k = static_cast<int>(e.kind);
  if (k < 0 || k >= kEventKindCount) return;
  std::unique_lock<std::mutex> lock(mutex_);
  if (failed_) return;
  ++counts_.offered;
  if (auto rate = options_.max_rate_hz.find(e.kind); rate != options_.max_rate_hz.end()) {
    auto last = last_sent_us_.find(e.kind);
    const auto min_gap_us = static_cast<int64_t>(std::llround(1e6 / rate->second));
    if (last != last_sent_us_.end() && e.t_us >= last->second && e.t_us - last->second < min_gap_us) {
      ++counts_.rate_limited;
      return;
    }
    last_sent_us_[e.kind] = e.t_us;
  }
  std::deque<Queued>& q = queues_[k];
  if (q.size() >= options_.queue_per_kind) {
    if (options_.wait_when_full) {
      room_.wait(lock, [&] { return q.size() < options_.queue_per_kind || failed_ || closing_; });
      if (failed_ || closing_) return;
    } else {
      q.pop_front();
      --queued_;
      ++counts_.dropped[e.kind];
    }
  }
  const int64_t now_us =
      std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
          .count();
  q.push_back({next_seq_++, e, now_us});
  ++queued_;
  lock.unlock();
  ready_.notify_one();
}

void OutputRunner::Run() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    ready_.wait(lock, [&] { return queued_ > 0 || closing_; });
    if (queued_ == 0 && closing_) return;
    // The oldest event across the kinds: the output sees the run's order.
    int best = -1;
    for (int k = 0; k < kEventKindCount; ++k) {
      if (!queues_[k].empty() && (best < 0 || queues_[k].front().seq < queues_[best].front().seq)) best = k;
    }
    Event e = std::move(queues_[best].front().event);
    const int64_t offered_wall_us = queues_[best].front().offered_wall_us;
    queues_[best].pop_front();
    --queued_;
    room_.notify_all();
    lock.unlock();
    std::string error;
    try {
      output_->SendOffered(e, offered_wall_us);
    } catch (const std::exception& ex) {
      error = ex.what();
    }
    lock.lock();
    if (!error.empty()) {
      // A failed output gets nothing more; the run goes on.
      failed_ = true;
      counts_.error = error;
      for (auto& q : queues_) q.clear();
      queued_ = 0;
      room_.notify_all();
      mbot::log::Error("output " + name_ + ": " + error + " (it gets nothing more; the run goes on)");
      return;
    }
    ++counts_.sent;
  }
}

OutputCounts OutputRunner::Close(bool interrupted) {
  StopThread();
  try {
    output_->Close(interrupted);
  } catch (const std::exception& e) {
    if (counts_.error.empty()) counts_.error = e.what();
    mbot::log::Error("output " + name_ + ": " + e.what());
  }
  return counts_;
}

}  // namespace mbot::msgs
