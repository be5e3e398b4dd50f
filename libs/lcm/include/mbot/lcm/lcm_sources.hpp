// The LCM transport's source and output types and their [source] / output keys:
//   source lcm_log    an LCM log (lcm-logger), every botlab message generation;
//   source lcm_live   a robot (or the simulated one) on the LCM bus, in wall-clock time;
//   source lcm_relay  a fault-injecting relay between two LCM groups;
//   output lcm        publishes the run's events on the LCM bus as the botlab's messages (a viewer,
//                     lcm-spy, another process);
//   output lcm_log    records them as an LCM log the replay pipeline reads like a robot's.
// Channel names are the pipeline's topics (msgs/topics.hpp, the botlab's names) unless a section's
// `rename` table says otherwise.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mbot/lcm/lcm_relay.hpp"
#include "mbot/msgs/live_source.hpp"
#include "mbot/msgs/source.hpp"
#include "mbot/msgs/topics.hpp"

namespace mbot::config {
class Section;
}

namespace mbot::lcmio {

// [source] type = lcm_log.
struct LcmLogOptions {
  // Records are re-sorted by event time within this window (lcm-logger writes them in arrival order,
  // which can run a few ms backwards).
  int64_t reorder_window_us = 100000;
};

// [source] type = lcm_live: a robot (or the simulated one) on the LCM bus, in wall-clock time (the
// keys every live transport shares).
using msgs::LiveSourceOptions;

// [source] type = lcm_relay (its path is the robot's URL).
struct RelaySourceOptions {
  RelayOptions relay;
  double duration_s = 0.0;
};

void ParseRelayOptions(config::Section& section, msgs::SourceOptions* options);

// Registers the LCM source and output types (idempotent).
void RegisterLcmTransport();

}  // namespace mbot::lcmio
