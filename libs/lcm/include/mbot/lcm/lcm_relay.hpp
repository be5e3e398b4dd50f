// A fault-injecting relay between two LCM groups: the robot (or the simulated one) publishes on one,
// the autonomy listens on the other, and every message crossing is subject to the faults a real
// radio link and a real robot have — loss, delay and jitter, duplicates, reordering, corrupted bytes,
// a channel going silent for a while. (The kernel here has no netem, so the relay is how faults are
// made.) Robot-to-autonomy and autonomy-to-robot channels are listed separately, so nothing the relay
// publishes comes back to it. `[source] type = lcm_relay` runs one (config/fault_relay.ini).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace mbot::lcmio {

struct FaultOptions {
  double drop_rate = 0.0;             // chance a message is lost
  double duplicate_rate = 0.0;        // chance it arrives twice
  double reorder_rate = 0.0;          // chance it is held back and sent after the channel's next message
  double corrupt_rate = 0.0;          // chance 1–4 of its bytes are changed (the receiver must reject or survive it)
  double delay_ms = 0.0;              // every message arrives this much later…
  double jitter_ms = 0.0;             // …plus a uniform 0…jitter (so messages of a channel may swap)
  std::vector<std::string> channels;  // the channels the faults apply to; empty: every relayed channel
  struct Silence {
    std::string channel;
    double at_s = 0.0, for_s = 0.0;  // from at_s after the relay starts, for for_s: nothing crosses
  };
  std::vector<Silence> silences;
  uint64_t seed = 1;
};

struct RelayOptions {
  std::string robot_url;     // the robot's group
  std::string autonomy_url;  // the autonomy's group
  std::vector<std::string> robot_to_autonomy;
  std::vector<std::string> autonomy_to_robot;
  FaultOptions faults;
};

struct RelayChannelStats {
  long long received = 0, relayed = 0, dropped = 0, duplicated = 0, reordered = 0, corrupted = 0, silenced = 0;
};

class LcmFaultRelay {
 public:
  // Opens both groups and subscribes; throws std::runtime_error naming a URL LCM cannot open.
  explicit LcmFaultRelay(const RelayOptions& options);
  ~LcmFaultRelay();
  LcmFaultRelay(const LcmFaultRelay&) = delete;
  LcmFaultRelay& operator=(const LcmFaultRelay&) = delete;

  // Relays for up to `ms` milliseconds: receives from both groups, publishes what is due.
  void Pump(int ms);
  double elapsed_s() const;
  const std::map<std::string, RelayChannelStats>& stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mbot::lcmio
