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

// [source] type = lcm_live: a robot (or the simulated one) on the LCM bus, in wall-clock time.
struct LiveSourceOptions {
  // The robot's channels the autonomy listens to (current mbot_lcm_msgs names).
  std::vector<std::string> channels = {msgs::topics::kLidar,      msgs::topics::kOdometry, msgs::topics::kEncoders,
                                       msgs::topics::kImu,        msgs::topics::kTimesync, msgs::topics::kPath,
                                       msgs::topics::kSystemReset};
  double duration_s = 0.0;           // 0: until Ctrl-C or a stage ends the run
  double end_after_silence_s = 0.0;  // > 0: the run ends when nothing arrived for this long
  // A watched channel silent this long is reported and the robot stopped (zero velocity published,
  // commands held back) until it is back.
  double stale_sensor_s = 1.0;
  std::vector<std::string> watched = {msgs::topics::kLidar, msgs::topics::kOdometry};
  std::string command_channel = msgs::topics::kVelocityCommand;
  double report_every_s = 10.0;  // a line with the loop rate and latency this often (0: never)
};

// [source] type = lcm_relay (its path is the robot's URL).
struct RelaySourceOptions {
  RelayOptions relay;
  double duration_s = 0.0;
};

// The lcm_live keys of [source].
LiveSourceOptions ParseLiveSourceOptions(config::Section& section);
void ParseRelayOptions(config::Section& section, msgs::SourceOptions* options);

// Registers the LCM source and output types (idempotent).
void RegisterLcmTransport();

}  // namespace mbot::lcmio
