// Live LCM: the MBot's own message bus. LcmNode subscribes to channels, decodes and validates every
// message at the edge (a count that disagrees with the payload, a wrong fingerprint, NaN, a
// truncated packet is rejected and counted, never passed on) and publishes events as the current
// mbot_lcm_msgs types. The live source (`[source] type = lcm_live`) is a Source and a Sink built on
// it; the simulated robot's side uses it through the `lcm_bridge` stage.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <set>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "mbot/msgs/events.hpp"
#include "mbot/msgs/live_source.hpp"
#include "mbot/msgs/source.hpp"

namespace mbot::lcmio {

inline constexpr const char* kDefaultLcmUrl = "udpm://239.255.76.67:7667?ttl=0";  // ttl=0: this machine only

struct LcmChannelStats {
  long long received = 0;    // messages that arrived
  long long rejected = 0;    // malformed: not passed on
  long long unknown = 0;     // of a type nobody knows
  long long published = 0;   // messages this node sent
  long long own_echoes = 0;  // this node's own messages looping back (multicast), ignored
  std::string last_error;    // why the last rejected one was
};

class LcmNode {
 public:
  // Opens `url` and subscribes to `channels` (exact names). Throws std::runtime_error naming the
  // URL when LCM cannot open it or subscribe (udpm sets up its receive socket lazily: a failure
  // there is logged by LCM and the node hears nothing; the live source's watchdog then says so).
  // A message this node itself published on a subscribed channel (multicast loops it back) is
  // recognised and ignored.
  LcmNode(const std::string& url, const std::vector<std::string>& channels, const msgs::ChannelRoles& roles);
  ~LcmNode();
  LcmNode(const LcmNode&) = delete;
  LcmNode& operator=(const LcmNode&) = delete;

  // Waits up to timeout_ms for a message, then takes every message already waiting. Good ones are
  // appended to `out` in arrival order, t_us = when LCM's receive thread got it (wall clock, µs
  // since the epoch: what lcm-logger stamps), stamp_us = the message's utime.
  void Poll(int timeout_ms, std::vector<msgs::Event>* out);
  // Publishes the event on its channel; false when the event has no LCM message (nothing sent).
  bool Publish(const msgs::Event& event);
  // Publishes raw bytes (tools and tests that send malformed packets on purpose); false when LCM
  // could not send them.
  bool PublishRaw(const std::string& channel, const std::vector<uint8_t>& data);
  bool subscribed(const std::string& channel) const;

  const std::map<std::string, LcmChannelStats>& stats() const { return stats_; }
  long long rejected_total() const;
  const std::string& url() const { return url_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string url_;
  msgs::ChannelRoles roles_;
  std::map<std::string, LcmChannelStats> stats_;
  std::set<std::string> subscribed_;
  static constexpr size_t kRecentPerChannel = 64;
  std::map<std::string, std::deque<size_t>> recent_;  // hashes of what was published, to spot echoes
  bool RecentlyPublished(const std::string& channel, size_t hash);
};

// Wall-clock time in µs since the epoch.
using msgs::WallClockUs;

// LCM takes a channel name as a regular expression: this one matches `channel` alone.
std::string LcmChannelPattern(const std::string& channel);

// The bytes LcmNode::Publish sends for `event` (empty when it has no LCM message).
std::vector<uint8_t> EncodeEvent(const msgs::Event& event);

}  // namespace mbot::lcmio
