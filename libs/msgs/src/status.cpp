#include "mbot/msgs/status.hpp"

namespace mbot::msgs {

const char* ToString(SlamMode mode) {
  switch (mode) {
    case SlamMode::kMappingOnly: return "mapping-only";
    case SlamMode::kActionOnly: return "action-only";
    case SlamMode::kLocalization: return "localization";
    case SlamMode::kFullSlam: return "full SLAM";
    case SlamMode::kGraphSlam: return "graph SLAM";
  }
  return "?";
}

const char* ToString(SlamState state) {
  switch (state) {
    case SlamState::kMapping: return "mapping";
    case SlamState::kLocalizing: return "localizing";
    case SlamState::kLocalized: return "localized";
    case SlamState::kLost: return "lost";
  }
  return "?";
}

namespace {
constexpr MissionState kAll[] = {MissionState::kInitializing, MissionState::kLocalizing,  MissionState::kWaiting,
                                 MissionState::kDriving,      MissionState::kExploring,   MissionState::kReturningHome,
                                 MissionState::kLifting,      MissionState::kSettingDown, MissionState::kArrived,
                                 MissionState::kCompleted,    MissionState::kIncomplete,  MissionState::kFailed};
}

const char* ToString(MissionState s) {
  switch (s) {
    case MissionState::kInitializing: return "initializing";
    case MissionState::kLocalizing: return "localizing";
    case MissionState::kWaiting: return "waiting";
    case MissionState::kDriving: return "driving";
    case MissionState::kExploring: return "exploring";
    case MissionState::kReturningHome: return "returning_home";
    case MissionState::kLifting: return "lifting";
    case MissionState::kSettingDown: return "setting_down";
    case MissionState::kArrived: return "arrived";
    case MissionState::kCompleted: return "completed";
    case MissionState::kIncomplete: return "incomplete";
    case MissionState::kFailed: return "failed";
  }
  return "?";
}

std::optional<MissionState> MissionStateFromString(const std::string& name) {
  for (MissionState s : kAll) {
    if (name == ToString(s)) return s;
  }
  return std::nullopt;
}

}  // namespace mbot::msgs
