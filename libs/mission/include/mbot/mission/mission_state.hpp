// The mission's state, typed: what the robot is doing for its task. Strings appear only at the
// edges (JSON reports, LCM status messages), through ToString / MissionStateFromString.
#pragma once

#include <optional>
#include <string>

namespace mbot::mission {

enum class MissionState {
  kInitializing,   // waiting for SLAM's first poses
  kLocalizing,     // standing still until global localization settles (warehouse)
  kWaiting,        // nothing to do yet (follow: no path received)
  kDriving,        // driving a path to a goal
  kExploring,      // exploring frontiers
  kReturningHome,  // exploration done: driving home and aligning there
  kLifting,        // warehouse: standing at a target
  kSettingDown,    // warehouse: standing at a drop-off
  kArrived,        // follow: at the end of a path, waiting for the next
  kCompleted,      // the task is done
  kIncomplete,     // exploration: home, but frontiers were left (the detail counts and places them)
  kFailed,         // the task cannot go on (the detail says why)
};

// snake_case names: "initializing", "returning_home", "setting_down" …
const char* ToString(MissionState state);
std::optional<MissionState> MissionStateFromString(const std::string& name);
// Completed, incomplete or failed: the mission commands nothing more.
inline bool IsFinal(MissionState s) {
  return s == MissionState::kCompleted || s == MissionState::kIncomplete || s == MissionState::kFailed;
}

struct MissionStatus {
  MissionState state = MissionState::kInitializing;
  std::string detail;  // for people: why, where, how well
};

}  // namespace mbot::mission
