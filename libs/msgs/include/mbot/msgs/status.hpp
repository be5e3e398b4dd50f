// Plain status and command types the stages publish: a velocity command, SLAM's status and the
// mission's state. Strings appear only at the edges (JSON reports, wire messages), through ToString.
#pragma once

#include <optional>
#include <string>

namespace mbot::msgs {

// Body-frame velocity command: forward speed (m/s) and counter-clockwise turn rate (rad/s).
struct VelocityCommand {
  double v_m_s = 0.0;
  double w_rad_s = 0.0;
};

// The SLAM system's modes (libs/mapping: slam.hpp says what each does).
enum class SlamMode { kMappingOnly, kActionOnly, kLocalization, kFullSlam, kGraphSlam };
const char* ToString(SlamMode mode);

// What SLAM's pose is worth, published as SLAM_STATUS: the mapping modes map; localization has not
// settled yet (global search), has settled, or has lost the robot.
enum class SlamState { kMapping, kLocalizing, kLocalized, kLost };
const char* ToString(SlamState state);  // "mapping", "localizing", "localized", "lost"

// SLAM's status: its state, its mode and the particles' spread.
struct SlamStatus {
  SlamState state = SlamState::kMapping;
  SlamMode mode = SlamMode::kFullSlam;
  double spread_m = 0.0;
  // What a person switched (the viewer; SlamControl): scans go into the map, scans correct the pose.
  bool mapping_on = true, localization_on = true;
};

// The mission's state: what the robot is doing for its task.
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

}  // namespace mbot::msgs
