#include "mbot/lcm/lcm_relay.hpp"

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
#include "mbot/lcm/fault_injector.hpp"
#include "mbot/lcm/lcm_live.hpp"
#include "mbot/lcm/lcm_sources.hpp"
#include "mbot/msgs/topics.hpp"

namespace mbot::lcmio {

using namespace msgs;  // the event vocabulary
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

struct LcmFaultRelay::Impl {
  // One direction: the group it listens to and the group it publishes on.
  struct Side {
    Impl* impl = nullptr;
    bool to_autonomy = true;
    void OnMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
      const auto* d = static_cast<const uint8_t*>(rbuf->data);
      impl->faults.Receive(to_autonomy, channel, std::vector<uint8_t>(d, d + rbuf->data_size), impl->Elapsed());
    }
  };

  RelayOptions o;
  lcm::LCM robot, autonomy;
  Side up, down;
  Clock::time_point start = Clock::now();
  FaultInjector faults;

  explicit Impl(const RelayOptions& options)
      : o(options), robot(options.robot_url), autonomy(options.autonomy_url), faults(options.faults) {
    if (!robot.good()) throw std::runtime_error("lcm_relay: cannot open robot_url '" + o.robot_url + "'");
    if (!autonomy.good()) throw std::runtime_error("lcm_relay: cannot open autonomy_url '" + o.autonomy_url + "'");
    up = {this, true};
    down = {this, false};
    for (const std::string& c : o.robot_to_autonomy) robot.subscribe(LcmChannelPattern(c), &Side::OnMessage, &up);
    for (const std::string& c : o.autonomy_to_robot) autonomy.subscribe(LcmChannelPattern(c), &Side::OnMessage, &down);
  }

  double Elapsed() const { return std::chrono::duration<double>(Clock::now() - start).count(); }

  void SendDue() {
    for (const FaultInjector::Message& p : faults.TakeDue(Elapsed())) {
      lcm::LCM& out = p.to_autonomy ? autonomy : robot;
      out.publish(p.channel, p.data.data(), static_cast<unsigned int>(p.data.size()));
    }
  }

  void Pump(int ms) {
    const double until = Elapsed() + ms * 1e-3;
    for (;;) {
      SendDue();
      const double now = Elapsed();
      if (now >= until) break;
      double wake = until;
      if (const std::optional<double> due = faults.next_due_s()) wake = std::min(wake, *due);
      const int wait_ms = static_cast<int>(std::max(0.0, (wake - now) * 1e3));
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

const std::map<std::string, RelayChannelStats>& LcmFaultRelay::stats() const { return impl_->faults.stats(); }

}  // namespace mbot::lcmio

namespace mbot::lcmio {

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
  RelaySourceOptions ro;
  RelayOptions& r = ro.relay;
  r.robot_url = o->path;
  r.autonomy_url = s.GetString("relay_url", "udpm://239.255.76.68:7668?ttl=0",
                               doc("the autonomy's LCM group, where the relay republishes the robot's messages"));
  r.robot_to_autonomy = s.GetList(
      "robot_to_autonomy",
      {topics::kLidar, topics::kOdometry, topics::kEncoders, topics::kImu, topics::kMotorPwm, topics::kMotorVelocity},
      doc("channels relayed from the robot's group to the autonomy's"));
  r.autonomy_to_robot = s.GetList("autonomy_to_robot",
                                  {topics::kVelocityCommand, topics::kSlamPose, topics::kSlamMap, topics::kSlamStatus,
                                   topics::kExplorationStatus, topics::kPath},
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
  ro.duration_s = s.GetDouble("duration_s", 0.0, doc("the relay stops after this long (0: never) [s]"), 0.0, 1e7);
  o->extra = ro;
}

namespace {

// The relay as a source: it relays between events and emits a RELAY_TICK heartbeat every 100 ms, so
// the pipeline keeps checking its stop flag; Details() is the per-channel account of the faults.
class LcmRelaySource : public Source {
  static RelayOptions WithSeed(const SourceOptions& o) {
    RelayOptions r = ExtraOr<RelaySourceOptions>(o).relay;
    r.faults.seed = o.seed;  // [pipeline] seed
    return r;
  }

 public:
  explicit LcmRelaySource(const SourceOptions& o)
      : relay_(WithSeed(o)), duration_s_(ExtraOr<RelaySourceOptions>(o).duration_s) {}
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

}  // namespace mbot::lcmio
