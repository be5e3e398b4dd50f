// `[source] type = lcm_live`: the autonomy's side of a robot on the LCM bus — a msgs::LiveSource
// (queue, stale-scan drop, sensor watchdog, latency report) on an LcmNode: the robot's sensor
// messages validated at the edge; velocity commands, SLAM pose, map and particles, paths and
// statuses published as the botlab's messages. t_us is when LCM's receive thread got a message.
#pragma once

#include <memory>

#include "mbot/msgs/live_source.hpp"

namespace mbot::lcmio {

std::unique_ptr<msgs::Source> OpenLcmLive(const msgs::SourceOptions& options);

}  // namespace mbot::lcmio
