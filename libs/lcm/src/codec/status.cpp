// The status family: exploration_status_t (the mission's state), slam_status_t, time sync, resets.
#include "codec.hpp"
#include "mbot_lcm_msgs/exploration_status_t.hpp"
#include "mbot_lcm_msgs/mbot_message_received_t.hpp"
#include "mbot_lcm_msgs/mbot_slam_reset_t.hpp"
#include "mbot_lcm_msgs/slam_status_t.hpp"
#include "mbot_legacy/exploration_status_t.hpp"
#include "mbot_legacy/message_received_t.hpp"
#include "mbot_legacy/timestamp_t.hpp"
#include "mbot_w23/mbot_system_reset_t.hpp"

namespace mbot::lcmio::lcm_adapter {

namespace {

// exploration_status_t's STATE_* and STATUS_* constants by value, as this stack's state names.
// exploration_status_t's states, in the order of its constants, as the mission's states.
constexpr msgs::MissionState kExplorationStates[] = {msgs::MissionState::kInitializing, msgs::MissionState::kExploring,
                                                     msgs::MissionState::kReturningHome, msgs::MissionState::kCompleted,
                                                     msgs::MissionState::kFailed};
const char* const kExplorationStatuses[] = {"in progress", "complete", "failed"};

}  // namespace

void AddStatusTypes(TypeTable& t) {
  t.Add(mbot_legacy::timestamp_t::getHash(), "timestamp_t", kLegacy, Other<mbot_legacy::timestamp_t>());
  t.Add(mbot_legacy::timestamp_t::getHash(), "timestamp_t", kW23, nullptr);
  t.Add(mbot_legacy::timestamp_t::getHash(), "timestamp_t", kCurrent, nullptr);
  t.Add(mbot_legacy::message_received_t::getHash(), "message_received_t", kLegacy,
        OtherWithString<mbot_legacy::message_received_t>(24, "channel"));
  t.Add(mbot_legacy::message_received_t::getHash(), "mbot_message_received_t", kCurrent, nullptr);
  t.Add(mbot_legacy::exploration_status_t::getHash(), "exploration_status_t", kLegacy,
        Other<mbot_legacy::exploration_status_t>());
  t.Add(mbot_legacy::exploration_status_t::getHash(), "exploration_status_t", kW23, nullptr);
  t.Add(mbot_lcm_msgs::exploration_status_t::getHash(), "exploration_status_t", kCurrent,
        [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
          mbot_lcm_msgs::exploration_status_t m{};
          if (!DecodeExact(d, n, &m, err)) return false;
          if (m.state < 0 || m.state > 4 || m.status < 0 || m.status > 2) {
            *err = "state " + std::to_string(m.state) + " / status " + std::to_string(m.status) +
                   " is not one of the botlab's";
            return false;
          }
          ev->kind = EventKind::kMissionStatus;
          ev->stamp_us = m.utime;
          // Home with frontiers left travels as "completed exploration" with status "failed".
          const bool incomplete = m.state == mbot_lcm_msgs::exploration_status_t::STATE_COMPLETED_EXPLORATION &&
                                  m.status == mbot_lcm_msgs::exploration_status_t::STATUS_FAILED;
          ev->payload = msgs::MissionStatus{incomplete ? msgs::MissionState::kIncomplete : kExplorationStates[m.state],
                                            kExplorationStatuses[m.status]};
          return true;
        });
  t.Add(mbot_lcm_msgs::slam_status_t::getHash(), "slam_status_t", kCurrent,
        OtherWithString<mbot_lcm_msgs::slam_status_t>(20, "map_path"));
  t.Add(mbot_lcm_msgs::mbot_slam_reset_t::getHash(), "mbot_slam_reset_t", kCurrent,
        OtherWithString<mbot_lcm_msgs::mbot_slam_reset_t>(20, "slam_map_location"));
  t.Add(mbot_w23::mbot_system_reset_t::getHash(), "mbot_system_reset_t", kW23, nullptr);
}

bool Encoder::Slam(const Event& ev, const SlamStatus& st) {
  // SLAM's status as slam_status_t's mode (its own states — localizing, localized, lost — have no
  // field there).
  mbot_lcm_msgs::slam_status_t m{};
  m.utime = ev.stamp_us;
  m.slam_mode = st.mode == SlamMode::kMappingOnly    ? 0
                : st.mode == SlamMode::kActionOnly   ? 1
                : st.mode == SlamMode::kLocalization ? 2
                                                     : 3;
  return Put(m);
}

bool Encoder::Mission(const Event& ev, const MissionStatus& st) {
  // A task's state as the nearest exploration_status_t state (a state of its own, e.g. driving or
  // lifting, is one in progress).
  using X = mbot_lcm_msgs::exploration_status_t;
  X m{};
  m.utime = ev.stamp_us;
  m.state = X::STATE_EXPLORING_MAP;
  for (int8_t k = 0; k < 5; ++k) {
    if (st.state == kExplorationStates[k]) m.state = k;
  }
  m.status = m.state == X::STATE_COMPLETED_EXPLORATION ? X::STATUS_COMPLETE
             : m.state == X::STATE_FAILED_EXPLORATION  ? X::STATUS_FAILED
                                                       : X::STATUS_IN_PROGRESS;
  if (st.state == MissionState::kIncomplete) {  // home, frontiers left: completed, not successfully
    m.state = X::STATE_COMPLETED_EXPLORATION;
    m.status = X::STATUS_FAILED;
  }
  return Put(m);
}

}  // namespace mbot::lcmio::lcm_adapter
