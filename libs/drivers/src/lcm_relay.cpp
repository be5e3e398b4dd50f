#include "mbot/drivers/lcm_relay.hpp"

#include <poll.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <optional>
#include <lcm/lcm-cpp.hpp>
#include <queue>
#include <random>
#include <set>
#include <stdexcept>
#include <cmath>
#include <cstdlib>

#include "mbot/common/config.hpp"
#include "mbot/drivers/lcm_live.hpp"
#include "mbot/drivers/source_options.hpp"

namespace mbot::drivers {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

struct LcmFaultRelay::Impl {
  struct Pending {
    Clock::time_point due;
    uint64_t order = 0;  // FIFO among messages due at the same instant
    bool to_autonomy = true;
    std::string channel;
    std::vector<uint8_t> data;
    bool operator>(const Pending& o) const { return due != o.due ? due > o.due : order > o.order; }
  };
  // One direction: the group it listens to and the group it publishes on.
  struct Side {
    Impl* impl = nullptr;
    bool to_autonomy = true;
    void OnMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
      impl->Receive(to_autonomy, channel, static_cast<const uint8_t*>(rbuf->data), rbuf->data_size);
    }
  };

  RelayOptions o;
  lcm::LCM robot, autonomy;
  Side up, down;
  Clock::time_point start = Clock::now();
  std::mt19937_64 rng;
  std::priority_queue<Pending, std::vector<Pending>, std::greater<>> queue;
  std::map<std::string, Pending> held;  // a message held back until the channel's next one (reordering)
  std::set<std::string> faulty;
  std::map<std::string, RelayChannelStats> stats;
  uint64_t order = 0;

  explicit Impl(const RelayOptions& options)
      : o(options), robot(options.robot_url), autonomy(options.autonomy_url), rng(options.faults.seed) {
    if (!robot.good()) throw std::runtime_error("lcm_relay: cannot open robot_url '" + o.robot_url + "'");
    if (!autonomy.good()) throw std::runtime_error("lcm_relay: cannot open autonomy_url '" + o.autonomy_url + "'");
    up = {this, true};
    down = {this, false};
    for (const std::string& c : o.robot_to_autonomy) robot.subscribe(LcmChannelPattern(c), &Side::OnMessage, &up);
    for (const std::string& c : o.autonomy_to_robot) autonomy.subscribe(LcmChannelPattern(c), &Side::OnMessage, &down);
    faulty.insert(o.faults.channels.begin(), o.faults.channels.end());
  }

  double Chance() { return std::uniform_real_distribution<double>(0.0, 1.0)(rng); }

  bool Silenced(const std::string& channel, double t_s) const {
    for (const FaultOptions::Silence& s : o.faults.silences) {
      if (s.channel == channel && t_s >= s.at_s && t_s < s.at_s + s.for_s) return true;
    }
    return false;
  }

  void Receive(bool to_autonomy, const std::string& channel, const uint8_t* data, size_t size) {
    RelayChannelStats& st = stats[channel];
    ++st.received;
    const Clock::time_point now = Clock::now();
    const double t_s = std::chrono::duration<double>(now - start).count();
    if (Silenced(channel, t_s)) {
      ++st.silenced;
      return;
    }
    Pending p{now, order++, to_autonomy, channel, std::vector<uint8_t>(data, data + size)};
    const FaultOptions& f = o.faults;
    if (!faulty.empty() && !faulty.count(channel)) {
      queue.push(std::move(p));
      return;
    }
    if (Chance() < f.drop_rate) {
      ++st.dropped;
      return;
    }
    if (!p.data.empty() && Chance() < f.corrupt_rate) {
      ++st.corrupted;
      const int n = 1 + static_cast<int>(rng() % 4);
      for (int i = 0; i < n; ++i) p.data[rng() % p.data.size()] = static_cast<uint8_t>(rng());
    }
    const double delay_ms = f.delay_ms + f.jitter_ms * Chance();
    p.due = now + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double, std::milli>(delay_ms));
    // A held message goes out right after this one.
    auto h = held.find(channel);
    std::optional<Pending> release;
    if (h != held.end()) {
      release = std::move(h->second);
      held.erase(h);
    }
    if (!release && Chance() < f.reorder_rate) {
      ++st.reordered;
      held.emplace(channel, std::move(p));
      return;
    }
    const bool twice = Chance() < f.duplicate_rate;
    const Clock::time_point due = p.due;
    if (twice) {
      ++st.duplicated;
      Pending copy = p;
      copy.order = order++;
      queue.push(std::move(copy));
    }
    queue.push(std::move(p));
    if (release) {  // the held message goes out right after this one: the two swapped places
      release->due = due;
      release->order = order++;
      queue.push(std::move(*release));
    }
  }

  void SendDue() {
    const Clock::time_point now = Clock::now();
    while (!queue.empty() && queue.top().due <= now) {
      const Pending& p = queue.top();
      lcm::LCM& out = p.to_autonomy ? autonomy : robot;
      out.publish(p.channel, p.data.data(), static_cast<unsigned int>(p.data.size()));
      ++stats[p.channel].relayed;
      queue.pop();
    }
  }

  void Pump(int ms) {
    const Clock::time_point until = Clock::now() + std::chrono::milliseconds(ms);
    for (;;) {
      SendDue();
      const Clock::time_point now = Clock::now();
      if (now >= until) break;
      Clock::time_point wake = until;
      if (!queue.empty()) wake = std::min(wake, queue.top().due);
      const int wait_ms = static_cast<int>(
          std::max<int64_t>(0, std::chrono::duration_cast<std::chrono::milliseconds>(wake - now).count()));
      pollfd fds[2] = {{robot.getFileno(), POLLIN, 0}, {autonomy.getFileno(), POLLIN, 0}};
      if (::poll(fds, 2, std::max(1, wait_ms)) > 0) {
        if (fds[0].revents & POLLIN) robot.handle();
        if (fds[1].revents & POLLIN) autonomy.handle();
      }
    }
  }
};

LcmFaultRelay::LcmFaultRelay(const RelayOptions& options) : impl_(std::make_unique<Impl>(options)) {}
LcmFaultRelay::~LcmFaultRelay() = default;

void LcmFaultRelay::Pump(int ms) { impl_->Pump(ms); }

double LcmFaultRelay::elapsed_s() const { return std::chrono::duration<double>(Clock::now() - impl_->start).count(); }

const std::map<std::string, RelayChannelStats>& LcmFaultRelay::stats() const { return impl_->stats; }

}  // namespace mbot::drivers

namespace mbot::drivers {

// "LIDAR@20+3": LIDAR silent from 20 s after the start, for 3 s.
FaultOptions::Silence ParseSilence(config::Section& s, const std::string& text) {
  const size_t at = text.find('@'), plus = text.find('+', at == std::string::npos ? 0 : at);
  FaultOptions::Silence out;
  char* end = nullptr;
  if (at == std::string::npos || plus == std::string::npos || at == 0) {
    s.Fail("silences", "'" + text + "' is not CHANNEL@START+SECONDS (e.g. LIDAR@20+3)");
  }
  out.channel = text.substr(0, at);
  const std::string a = text.substr(at + 1, plus - at - 1), b = text.substr(plus + 1);
  out.at_s = std::strtod(a.c_str(), &end);
  const bool a_ok = !a.empty() && *end == '\0';
  out.for_s = std::strtod(b.c_str(), &end);
  const bool b_ok = !b.empty() && *end == '\0';
  if (!a_ok || !b_ok || !std::isfinite(out.at_s) || !std::isfinite(out.for_s) || out.at_s < 0 || out.for_s <= 0 ||
      out.at_s > 1e7 || out.for_s > 1e7) {
    s.Fail("silences", "'" + text + "': START and SECONDS must be numbers, START >= 0 and SECONDS > 0");
  }
  return out;
}

void ParseRelayOptions(config::Section& s, SourceOptions* o) {
  const auto doc = [](const char* text) { return std::string("lcm_relay: ") + text; };
  RelayOptions& r = o->relay;
  r.robot_url = o->path;
  r.autonomy_url = s.GetString("relay_url", "udpm://239.255.76.68:7668?ttl=0",
                               doc("the autonomy's LCM group, where the relay republishes the robot's messages"));
  r.robot_to_autonomy = s.GetList(
      "robot_to_autonomy", {"LIDAR", "MBOT_ODOMETRY", "MBOT_ENCODERS", "MBOT_IMU", "MBOT_MOTOR_PWM", "MBOT_MOTOR_VEL"},
      doc("channels relayed from the robot's group to the autonomy's"));
  r.autonomy_to_robot =
      s.GetList("autonomy_to_robot",
                {"MBOT_VEL_CMD", "SLAM_POSE", "SLAM_MAP", "SLAM_STATUS", "EXPLORATION_STATUS", "CONTROLLER_PATH"},
                doc("channels relayed from the autonomy's group to the robot's"));
  FaultOptions& f = r.faults;
  f.drop_rate = s.GetDouble("drop_rate", 0.0, doc("chance a message is lost"), 0.0, 1.0);
  f.duplicate_rate = s.GetDouble("duplicate_rate", 0.0, doc("chance a message arrives twice"), 0.0, 1.0);
  f.reorder_rate =
      s.GetDouble("reorder_rate", 0.0, doc("chance a message is sent after its channel's next one"), 0.0, 1.0);
  f.corrupt_rate = s.GetDouble("corrupt_rate", 0.0, doc("chance 1-4 bytes of a message are changed"), 0.0, 1.0);
  f.delay_ms = s.GetDouble("delay_ms", 0.0, doc("every message arrives this much later [ms]"), 0.0, 60000.0);
  f.jitter_ms = s.GetDouble("jitter_ms", 0.0, doc("plus a uniform 0..jitter_ms [ms]"), 0.0, 60000.0);
  f.channels = s.GetList("fault_channels", {}, doc("the channels the faults apply to (empty: every relayed one)"));
  for (const std::string& text :
       s.GetList("silences", {}, doc("CHANNEL@START+SECONDS: nothing crosses on CHANNEL for SECONDS from START"))) {
    f.silences.push_back(ParseSilence(s, text));
  }
  o->relay_duration_s = s.GetDouble("duration_s", 0.0, doc("the relay stops after this long (0: never) [s]"), 0.0, 1e7);
}

namespace {

// The relay as a source: it relays between events and emits a RELAY_TICK heartbeat every 100 ms, so
// the pipeline keeps checking its stop flag; Details() is the per-channel account of the faults.
class LcmRelaySource : public Source {
  static RelayOptions WithSeed(const SourceOptions& o) {
    RelayOptions r = o.relay;
    r.faults.seed = o.seed;  // [pipeline] seed
    return r;
  }

 public:
  explicit LcmRelaySource(const SourceOptions& o) : relay_(WithSeed(o)), duration_s_(o.relay_duration_s) {}
  std::optional<Event> Next() override {
    if (duration_s_ > 0 && relay_.elapsed_s() >= duration_s_) return std::nullopt;
    relay_.Pump(100);
    const int64_t t = WallClockUs();
    return Event{t, t, "RELAY_TICK", EventKind::kOther, {}};
  }
  double Progress() const override { return duration_s_ > 0 ? std::min(1.0, relay_.elapsed_s() / duration_s_) : 0; }
  std::string Format() const override { return "LCM fault relay"; }
  std::vector<std::pair<std::string, std::string>> Details() const override {
    std::vector<std::pair<std::string, std::string>> out;
    for (const auto& [channel, st] : relay_.stats()) {
      out.emplace_back("relay " + channel,
                       std::to_string(st.received) + " received, " + std::to_string(st.relayed) + " relayed, " +
                           std::to_string(st.dropped) + " dropped, " + std::to_string(st.duplicated) + " duplicated, " +
                           std::to_string(st.reordered) + " reordered, " + std::to_string(st.corrupted) +
                           " corrupted, " + std::to_string(st.silenced) + " silenced");
    }
    return out;
  }

 private:
  LcmFaultRelay relay_;
  double duration_s_;
};

}  // namespace

std::unique_ptr<Source> OpenLcmRelay(const SourceOptions& options) { return std::make_unique<LcmRelaySource>(options); }

}  // namespace mbot::drivers
