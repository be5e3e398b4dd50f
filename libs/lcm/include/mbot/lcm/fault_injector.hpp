// The relay's faults as a policy of their own: what happens to each message crossing (lost, held
// back and sent after the channel's next one, sent twice, 1-4 bytes changed, delayed with jitter,
// silenced for a while) and when it is due, on the caller's clock (seconds since the relay
// started) and a seeded generator — so the faults are tested without a bus, and the same seed
// makes the same faults.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <queue>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "mbot/lcm/lcm_relay.hpp"

namespace mbot::lcmio {

class FaultInjector {
 public:
  struct Message {
    double due_s = 0;
    uint64_t order = 0;  // FIFO among messages due at the same instant
    bool to_autonomy = true;
    std::string channel;
    std::vector<uint8_t> data;
    bool operator>(const Message& o) const { return due_s != o.due_s ? due_s > o.due_s : order > o.order; }
  };

  explicit FaultInjector(const FaultOptions& options);

  // A message that arrived at `t_s`: it is queued (when not lost or silenced) with its faults.
  void Receive(bool to_autonomy, const std::string& channel, std::vector<uint8_t> data, double t_s);
  // The queued messages due at `t_s`, in the order they go out (counted as relayed).
  std::vector<Message> TakeDue(double t_s);
  // When the next queued message is due, if any.
  std::optional<double> next_due_s() const;

  const std::map<std::string, RelayChannelStats>& stats() const { return stats_; }

 private:
  double Chance() { return std::uniform_real_distribution<double>(0.0, 1.0)(rng_); }
  bool Silenced(const std::string& channel, double t_s) const;

  FaultOptions o_;
  std::mt19937_64 rng_;
  std::priority_queue<Message, std::vector<Message>, std::greater<>> queue_;
  std::map<std::string, Message> held_;  // a message held back until the channel's next one (reordering)
  std::set<std::string> faulty_;
  std::map<std::string, RelayChannelStats> stats_;
  uint64_t order_ = 0;
};

}  // namespace mbot::lcmio
