// The LCM codec's shared pieces: one table of fingerprints → decoders that the message families
// fill (sensors.cpp, poses.cpp, maps.cpp, status.cpp, vision.cpp, forklift.cpp), the checks every
// decoder runs before lcm-gen's code touches a payload, and the encoder — an EventVisitor whose
// methods each family defines for its kinds.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "../lcm_messages.hpp"
#include "mbot/msgs/events.hpp"
#include "mbot/msgs/visitor.hpp"

namespace mbot::lcmio::lcm_adapter {

using namespace msgs;  // the event vocabulary

using Decoder =
    std::function<bool(const std::string& channel, const uint8_t*, size_t, const ChannelRoles&, Event*, std::string*)>;

struct Entry {
  TypeInfo info;
  Decoder decode;
};

// Fingerprint → type; a fingerprint added again (the same layout in another generation) keeps its
// first decoder and gains the name and generation (a null decoder only names them).
class TypeTable {
 public:
  void Add(int64_t hash, const std::string& type, const std::string& generation, Decoder decode);
  const std::map<int64_t, Entry>& entries() const { return entries_; }

 private:
  std::map<int64_t, Entry> entries_;
};

// The generations' names, as --list-types and inspect print them.
inline const std::string kLegacy = "legacy 2017-2022", kW23 = "W23", kCurrent = "2023+", kMaebot = "Maebot",
                         kOwn = "mbot_nav";

// Each family adds its types; the table is built in this order.
void AddSensorTypes(TypeTable& t);    // lidar, encoders, IMU, motor commands and speeds
void AddPoseTypes(TypeTable& t);      // poses, paths, particles
void AddMapTypes(TypeTable& t);       // occupancy grids
void AddStatusTypes(TypeTable& t);    // exploration and SLAM status, time sync, resets
void AddVisionTypes(TypeTable& t);    // AprilTag arrays, camera frames
void AddForkliftTypes(TypeTable& t);  // the forklift's command and status

// Events → the current (2023+) mbot_lcm_msgs message each family's channel carries.
class Encoder : public EventVisitor {
 public:
  explicit Encoder(std::vector<uint8_t>* out) : out_(out) {}
  // sensors.cpp
  bool Lidar(const Event& ev, const LidarScan& scan) override;
  bool Encoders(const Event& ev, const EncoderTicks& e) override;
  bool ImuReading(const Event& ev, const Imu& imu) override;
  bool Motors(const Event& ev, const MotorCommand& c) override;
  bool Wheels(const Event& ev, const WheelSpeeds& w) override;
  // poses.cpp
  bool Pose(const Event& ev, const Pose2D& p) override;
  bool PathPoses(const Event& ev, const Path& path) override;
  bool ParticleSet(const Event& ev, const Particles& p) override;
  // maps.cpp
  bool Map(const Event& ev, const OccupancyGrid& grid) override;
  // status.cpp
  bool Slam(const Event& ev, const SlamStatus& st) override;
  bool Mission(const Event& ev, const MissionStatus& st) override;
  // vision.cpp
  bool Tags(const Event& ev, const TagSightings& tags) override;
  bool Frame(const Event& ev, const CameraFrame& f) override;
  // forklift.cpp
  bool Forklift(const Event& ev, const ForkliftCommand& c) override;
  bool ForkliftState(const Event& ev, const ForkliftStatus& f) override;

 private:
  template <typename T>
  bool Put(const T& m) {
    out_->resize(static_cast<size_t>(m.getEncodedSize()));
    m.encode(out_->data(), 0, static_cast<int>(out_->size()));
    return true;
  }
  std::vector<uint8_t>* out_;
};

inline int32_t ReadI32(const uint8_t* p) {
  return static_cast<int32_t>((uint32_t(p[0]) << 24) | (uint32_t(p[1]) << 16) | (uint32_t(p[2]) << 8) | p[3]);
}

// Checks the int32 count at `offset` against the bytes left, before the generated decoder sizes a
// vector by it (a corrupt count would otherwise allocate gigabytes or throw).
inline bool CheckCount(const uint8_t* data, size_t size, size_t offset, size_t element_bytes, const char* field,
                       std::string* error) {
  if (size < offset + 4) {
    *error = "message too short (" + std::to_string(size) + " bytes) to hold " + field;
    return false;
  }
  const int32_t n = ReadI32(data + offset);
  if (n < 0 || uint64_t(n) * element_bytes > size - offset - 4) {
    *error = std::string(field) + " = " + std::to_string(n) + " disagrees with the payload (" + std::to_string(size) +
             " bytes)";
    return false;
  }
  return true;
}

// Checks the int32 length of a string at `offset` (lcm-gen counts the closing NUL, so at least 1)
// against the bytes left: lcm-gen's decoder computes `length - 1` and would overflow on INT32_MIN.
inline bool CheckString(const uint8_t* data, size_t size, size_t offset, const char* field, std::string* error) {
  if (size < offset + 4) {
    *error = "message too short (" + std::to_string(size) + " bytes) to hold " + field;
    return false;
  }
  const int32_t n = ReadI32(data + offset);
  if (n < 1 || uint64_t(n) > size - offset - 4) {
    *error = std::string(field) + " length " + std::to_string(n) + " disagrees with the payload (" +
             std::to_string(size) + " bytes)";
    return false;
  }
  return true;
}

// Runs the lcm-gen decoder and insists it consumed exactly the payload.
template <typename T>
bool DecodeExact(const uint8_t* data, size_t size, T* msg, std::string* error) {
  int used = -1;
  try {
    used = msg->decode(data, 0, static_cast<int>(size));
  } catch (const std::exception& e) {
    *error = std::string("decode failed: ") + e.what();
    return false;
  }
  if (used < 0) {
    *error = "payload shorter than its fields and counts require (" + std::to_string(size) + " bytes)";
    return false;
  }
  if (static_cast<size_t>(used) != size) {
    *error = "counts account for " + std::to_string(used) + " of " + std::to_string(size) +
             " payload bytes (array lengths disagree with their count field)";
    return false;
  }
  return true;
}

inline bool In(const std::vector<std::string>& list, const std::string& channel) {
  return std::find(list.begin(), list.end(), channel) != list.end();
}

inline bool Finite(double a, double b, double c) { return std::isfinite(a) && std::isfinite(b) && std::isfinite(c); }

// A type the pipeline recognises but does not use: validated, counted, not converted.
template <typename T>
Decoder Other(size_t count_offset = 0, size_t element_bytes = 0, const char* field = nullptr) {
  return [=](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
    if (field && !CheckCount(d, n, count_offset, element_bytes, field, err)) return false;
    T m{};
    if (!DecodeExact(d, n, &m, err)) return false;
    ev->kind = EventKind::kOther;
    ev->stamp_us = n >= 16 ? Fingerprint(d + 8, 8) : 0;  // every such type starts with utime
    return true;
  };
}

// A message of no interest whose one string (its length at `string_offset`) is checked first.
template <typename T>
Decoder OtherWithString(size_t string_offset, const char* field) {
  return [=](const std::string& channel, const uint8_t* d, size_t n, const ChannelRoles& roles, Event* ev,
             std::string* err) {
    if (!CheckString(d, n, string_offset, field, err)) return false;
    return Other<T>()(channel, d, n, roles, ev, err);
  };
}

}  // namespace mbot::lcmio::lcm_adapter
