// LCM message → Event adapter (the one place that knows the botlab wire types). Each known
// fingerprint maps to a decoder; fingerprints are shared by generations whose layouts agree.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mbot/msgs/events.hpp"
#include "mbot/msgs/source.hpp"

namespace mbot::lcmio::lcm_adapter {

using namespace msgs;  // the event vocabulary

struct TypeInfo {
  std::string type;        // e.g. "lidar_t" or "pose_xyt_t/odometry_t/pose2D_t"
  std::string generation;  // e.g. "legacy 2017-2022, W23, 2023+"
};

// Reads the 8-byte fingerprint at the start of an LCM payload (0 when shorter than 8 bytes).
int64_t Fingerprint(const uint8_t* data, size_t size);

// The type registered for a fingerprint, or nullptr when unknown.
const TypeInfo* LookUp(int64_t fingerprint);

// Decodes one message into `event` (kind, stamp_us, payload; t_us and channel are set by the
// caller). Returns false with `error` set when the message is malformed: a count that disagrees
// with the payload length, trailing bytes, non-finite poses. Never reads out of bounds.
bool Decode(const std::string& channel, const uint8_t* data, size_t size, const ChannelRoles& roles, Event* event,
            std::string* error);

// Encodes an event as the current (2023+) mbot_lcm_msgs message the botlab publishes on its
// channel: lidar_t (angles clockwise again), pose2D_t for every pose kind, mbot_encoders_t,
// mbot_imu_t, twist2D_t (velocity commands), mbot_motor_pwm_t, mbot_motor_vel_t, occupancy_grid_t
// (maps), path2D_t (paths), particles_t, slam_status_t (kSlamStatus) and
// exploration_status_t (kMissionStatus: the task's state as the botlab's constants) and
// mbot_apriltag_array_t (kTagSightings, as the botlab's publisher: mm, degrees). Returns false, leaving `out`
// empty, for kinds that have no such message (calibration samples, plan requests, others).
bool Encode(const Event& event, std::vector<uint8_t>* out);

// All registered fingerprints (for tests and --list-types).
std::vector<std::pair<int64_t, TypeInfo>> KnownTypes();

}  // namespace mbot::lcmio::lcm_adapter
