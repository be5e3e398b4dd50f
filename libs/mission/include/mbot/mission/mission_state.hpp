// The mission's state is the message vocabulary's (libs/msgs: status.hpp); the mission library
// drives it under these names.
#pragma once

#include "mbot/msgs/status.hpp"

namespace mbot::mission {

using msgs::IsFinal;
using msgs::MissionState;
using msgs::MissionStateFromString;
using msgs::MissionStatus;
using msgs::ToString;

}  // namespace mbot::mission
