#include "mbot/mission/mission_state.hpp"

namespace mbot::mission {

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

}  // namespace mbot::mission
