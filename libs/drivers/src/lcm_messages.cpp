#include "lcm_messages.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>

#include "maebot/maebot_encoders_t.hpp"
#include "maebot/maebot_imu_t.hpp"
#include "maebot/maebot_motor_command_t.hpp"
#include "mbot_lcm_msgs/exploration_status_t.hpp"
#include "mbot_lcm_msgs/mbot_apriltag_array_t.hpp"
#include "mbot_lcm_msgs/mbot_encoders_t.hpp"
#include "mbot_lcm_msgs/mbot_imu_t.hpp"
#include "mbot_lcm_msgs/mbot_message_received_t.hpp"
#include "mbot_lcm_msgs/mbot_motor_pwm_t.hpp"
#include "mbot_lcm_msgs/mbot_motor_vel_t.hpp"
#include "mbot_lcm_msgs/mbot_slam_reset_t.hpp"
#include "mbot_lcm_msgs/pose2D_t.hpp"
#include "mbot_lcm_msgs/slam_status_t.hpp"
#include "mbot_lcm_msgs/twist2D_t.hpp"
#include "mbot_legacy/exploration_status_t.hpp"
#include "mbot_nav_msgs/mbot_forklift_cmd_t.hpp"
#include "mbot_nav_msgs/mbot_forklift_status_t.hpp"
#include "mbot_nav_msgs/mbot_image_t.hpp"
#include "mbot_legacy/lidar_t.hpp"
#include "mbot_legacy/mbot_encoder_t.hpp"
#include "mbot_legacy/mbot_imu_t.hpp"
#include "mbot_legacy/mbot_motor_command_t.hpp"
#include "mbot_legacy/message_received_t.hpp"
#include "mbot_legacy/occupancy_grid_t.hpp"
#include "mbot_legacy/particles_t.hpp"
#include "mbot_legacy/pose_xyt_t.hpp"
#include "mbot_legacy/robot_path_t.hpp"
#include "mbot_legacy/timestamp_t.hpp"
#include "mbot_w23/mbot_state_t.hpp"
#include "mbot_w23/mbot_system_reset_t.hpp"
#include "mbot_w23/mbot_wheel_ctrl_t.hpp"
#include "mbot_w23/occupancy_grid_t.hpp"

namespace mbot::drivers::lcm_adapter {
int64_t Fingerprint(const uint8_t* data, size_t size);

namespace {

using Decoder =
    std::function<bool(const std::string& channel, const uint8_t*, size_t, const ChannelRoles&, Event*, std::string*)>;

struct Entry {
  TypeInfo info;
  Decoder decode;
};

int32_t ReadI32(const uint8_t* p) {
  return static_cast<int32_t>((uint32_t(p[0]) << 24) | (uint32_t(p[1]) << 16) | (uint32_t(p[2]) << 8) | p[3]);
}

// Checks the int32 count at `offset` against the bytes left, before the generated decoder sizes a
// vector by it (a corrupt count would otherwise allocate gigabytes or throw).
bool CheckCount(const uint8_t* data, size_t size, size_t offset, size_t element_bytes, const char* field,
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
bool CheckString(const uint8_t* data, size_t size, size_t offset, const char* field, std::string* error) {
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

bool In(const std::vector<std::string>& list, const std::string& channel) {
  return std::find(list.begin(), list.end(), channel) != list.end();
}

bool Finite(double a, double b, double c) { return std::isfinite(a) && std::isfinite(b) && std::isfinite(c); }

template <typename Lidar>
bool DecodeLidar(const uint8_t* d, size_t n, Event* ev, std::string* err) {
  if (!CheckCount(d, n, 16, 20, "num_ranges", err)) return false;
  Lidar m{};
  if (!DecodeExact(d, n, &m, err)) return false;
  LidarScan scan;
  scan.ranges_m = std::move(m.ranges);
  scan.angles_rad = std::move(m.thetas);
  scan.beam_times_us = std::move(m.times);
  scan.intensities = std::move(m.intensities);
  // lidar_t thetas grow clockwise (the RPLidar's own convention, which the botlab code undoes with
  // θ_robot − θ_beam); events carry counter-clockwise angles, so negate them once here.
  for (float& a : scan.angles_rad) {
    if (!std::isfinite(a)) {
      *err = "non-finite beam angle";
      return false;
    }
    a = -a;
  }
  ev->kind = EventKind::kLidar;
  ev->stamp_us = m.utime;
  ev->payload = std::move(scan);
  return true;
}

bool DecodePose(const std::string& channel, const uint8_t* d, size_t n, const ChannelRoles& roles, Event* ev,
                std::string* err) {
  mbot_legacy::pose_xyt_t m{};
  if (!DecodeExact(d, n, &m, err)) return false;
  if (!Finite(m.x, m.y, m.theta)) {
    *err = "non-finite pose";
    return false;
  }
  ev->stamp_us = m.utime;
  ev->payload = motion::Pose2D{m.x, m.y, m.theta};
  if (In(roles.ground_truth, channel))
    ev->kind = EventKind::kGroundTruth;
  else if (In(roles.odometry, channel))
    ev->kind = EventKind::kOdometry;
  else if (In(roles.reference_pose, channel))
    ev->kind = EventKind::kReferencePose;
  else
    ev->kind = EventKind::kOther;
  return true;
}

template <typename Grid>
bool DecodeGrid(const uint8_t* d, size_t n, size_t count_offset, Event* ev, std::string* err) {
  if (!CheckCount(d, n, count_offset, 1, "num_cells", err)) return false;
  Grid m{};
  if (!DecodeExact(d, n, &m, err)) return false;
  if (m.width < 0 || m.height < 0 || int64_t(m.width) * m.height != m.num_cells || !(m.meters_per_cell > 0.0f) ||
      !std::isfinite(m.origin_x) || !std::isfinite(m.origin_y)) {
    *err = "grid " + std::to_string(m.width) + "x" + std::to_string(m.height) + " does not match num_cells " +
           std::to_string(m.num_cells) + " or has a bad resolution/origin";
    return false;
  }
  auto grid = std::make_shared<mapping::OccupancyGrid>(m.width, m.height, m.meters_per_cell, m.origin_x, m.origin_y);
  std::copy(m.cells.begin(), m.cells.end(), grid->cells().begin());
  for (auto& c : grid->cells()) c = std::max<int8_t>(c, -127);  // -128 is outside the log-odds range
  ev->kind = EventKind::kMap;
  ev->stamp_us = m.utime;
  ev->payload = std::shared_ptr<const mapping::OccupancyGrid>(grid);
  return true;
}

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

// exploration_status_t's STATE_* and STATUS_* constants by value, as this stack's state names.
// exploration_status_t's states, in the order of its constants, as the mission's states.
constexpr mission::MissionState kExplorationStates[] = {
    mission::MissionState::kInitializing, mission::MissionState::kExploring, mission::MissionState::kReturningHome,
    mission::MissionState::kCompleted, mission::MissionState::kFailed};
const char* const kExplorationStatuses[] = {"in progress", "complete", "failed"};

std::map<int64_t, Entry> BuildTable() {
  std::map<int64_t, Entry> t;
  auto add = [&t](int64_t hash, const std::string& type, const std::string& gen, Decoder dec) {
    auto it = t.find(hash);
    if (it == t.end()) {
      t.emplace(hash, Entry{TypeInfo{type, gen}, std::move(dec)});
    } else {  // same layout in several generations: one decoder, all names
      if (it->second.info.type.find(type) == std::string::npos) it->second.info.type += "/" + type;
      if (it->second.info.generation.find(gen) == std::string::npos) it->second.info.generation += ", " + gen;
    }
  };
  const std::string kLegacy = "legacy 2017-2022", kW23 = "W23", kCurrent = "2023+", kMaebot = "Maebot";

  Decoder lidar = [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
    return DecodeLidar<mbot_legacy::lidar_t>(d, n, ev, err);
  };
  add(mbot_legacy::lidar_t::getHash(), "lidar_t", kLegacy, lidar);
  add(mbot_legacy::lidar_t::getHash(), "lidar_t", kW23, lidar);
  add(mbot_legacy::lidar_t::getHash(), "lidar_t", kCurrent, lidar);
  add(mbot_legacy::lidar_t::getHash(), "rplidar_laser_t", kMaebot, lidar);

  add(mbot_legacy::pose_xyt_t::getHash(), "pose_xyt_t", kLegacy, DecodePose);
  add(mbot_legacy::pose_xyt_t::getHash(), "odometry_t", kW23, DecodePose);
  add(mbot_lcm_msgs::pose2D_t::getHash(), "pose2D_t", kCurrent, DecodePose);

  add(mbot_legacy::mbot_encoder_t::getHash(), "mbot_encoder_t", kLegacy,
      [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
        mbot_legacy::mbot_encoder_t m{};
        if (!DecodeExact(d, n, &m, err)) return false;
        ev->kind = EventKind::kEncoders;
        ev->stamp_us = m.utime;
        ev->payload = EncoderTicks{m.leftticks, m.rightticks, m.left_delta, m.right_delta, 0};
        return true;
      });
  add(mbot_legacy::mbot_encoder_t::getHash(), "mbot_encoder_t", kW23, nullptr);
  add(mbot_lcm_msgs::mbot_encoders_t::getHash(), "mbot_encoders_t", kCurrent,
      [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
        mbot_lcm_msgs::mbot_encoders_t m{};
        if (!DecodeExact(d, n, &m, err)) return false;
        ev->kind = EventKind::kEncoders;
        ev->stamp_us = m.utime;
        ev->payload = EncoderTicks{m.ticks[0], m.ticks[1], m.delta_ticks[0], m.delta_ticks[1], m.delta_time};
        return true;
      });
  add(maebot::maebot_encoders_t::getHash(), "maebot_encoders_t", kMaebot,
      [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
        maebot::maebot_encoders_t m{};
        if (!DecodeExact(d, n, &m, err)) return false;
        ev->kind = EventKind::kEncoders;
        ev->stamp_us = m.utime;
        ev->payload = EncoderTicks{m.left_ticks_total, m.right_ticks_total, 0, 0, 0};
        return true;
      });

  add(mbot_legacy::mbot_imu_t::getHash(), "mbot_imu_t", kLegacy,
      [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
        mbot_legacy::mbot_imu_t m{};
        if (!DecodeExact(d, n, &m, err)) return false;
        Imu imu;
        for (int i = 0; i < 3; ++i) {
          imu.gyro_rad_s[i] = m.gyro[i];
          imu.accel_m_s2[i] = m.accel[i];
          imu.angles_rpy_rad[i] = m.tb_angles[i];
        }
        imu.has_angles = true;
        ev->kind = EventKind::kImu;
        ev->stamp_us = m.utime;
        ev->payload = imu;
        return true;
      });
  add(mbot_legacy::mbot_imu_t::getHash(), "mbot_imu_t", kW23, nullptr);
  add(mbot_lcm_msgs::mbot_imu_t::getHash(), "mbot_imu_t", kCurrent,
      [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
        mbot_lcm_msgs::mbot_imu_t m{};
        if (!DecodeExact(d, n, &m, err)) return false;
        Imu imu;
        for (int i = 0; i < 3; ++i) {
          imu.gyro_rad_s[i] = m.gyro[i];
          imu.accel_m_s2[i] = m.accel[i];
          imu.angles_rpy_rad[i] = m.angles_rpy[i];
        }
        imu.has_angles = true;
        ev->kind = EventKind::kImu;
        ev->stamp_us = m.utime;
        ev->payload = imu;
        return true;
      });
  add(maebot::maebot_imu_t::getHash(), "maebot_imu_t", kMaebot,
      [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
        maebot::maebot_imu_t m{};
        if (!DecodeExact(d, n, &m, err)) return false;
        Imu imu;
        for (int i = 0; i < 3; ++i) {
          imu.gyro_rad_s[i] = m.raw_angular_velocity[i];
          imu.accel_m_s2[i] = m.raw_acceleration[i];
          imu.angles_rpy_rad[i] = m.raw_orientation[i];
        }
        imu.has_angles = true;
        ev->kind = EventKind::kImu;
        ev->stamp_us = m.utime;
        ev->payload = imu;
        return true;
      });

  add(mbot_legacy::mbot_motor_command_t::getHash(), "mbot_motor_command_t", kLegacy,
      [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
        mbot_legacy::mbot_motor_command_t m{};
        if (!DecodeExact(d, n, &m, err)) return false;
        ev->kind = EventKind::kMotorCommand;
        ev->stamp_us = m.utime;
        ev->payload = MotorCommand::Velocity(m.trans_v, m.angular_v);
        return true;
      });
  add(mbot_legacy::mbot_motor_command_t::getHash(), "mbot_motor_command_t", kW23, nullptr);
  add(mbot_lcm_msgs::twist2D_t::getHash(), "twist2D_t", kCurrent,
      [](const std::string& ch, const uint8_t* d, size_t n, const ChannelRoles& roles, Event* ev, std::string* err) {
        mbot_lcm_msgs::twist2D_t m{};
        if (!DecodeExact(d, n, &m, err)) return false;
        ev->stamp_us = m.utime;
        ev->kind = In(roles.velocity_command, ch) ? EventKind::kMotorCommand : EventKind::kOther;
        ev->payload = MotorCommand::Velocity(m.vx, m.wz);
        return true;
      });
  add(mbot_lcm_msgs::mbot_motor_pwm_t::getHash(), "mbot_motor_pwm_t", kCurrent,
      [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
        mbot_lcm_msgs::mbot_motor_pwm_t m{};
        if (!DecodeExact(d, n, &m, err)) return false;
        ev->kind = EventKind::kMotorCommand;
        ev->stamp_us = m.utime;
        ev->payload = MotorCommand::Pwm(m.pwm[0], m.pwm[1]);
        return true;
      });
  add(mbot_lcm_msgs::mbot_motor_vel_t::getHash(), "mbot_motor_vel_t", kCurrent,
      [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
        mbot_lcm_msgs::mbot_motor_vel_t m{};
        if (!DecodeExact(d, n, &m, err)) return false;
        ev->kind = EventKind::kWheelSpeed;  // measured wheel speeds, not a command
        ev->stamp_us = m.utime;
        ev->payload = WheelSpeeds{m.velocity[0], m.velocity[1]};
        return true;
      });
  add(maebot::maebot_motor_command_t::getHash(), "maebot_motor_command_t", kMaebot,
      [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
        maebot::maebot_motor_command_t m{};
        if (!DecodeExact(d, n, &m, err)) return false;
        ev->kind = EventKind::kMotorCommand;
        ev->stamp_us = m.utime;
        ev->payload = MotorCommand::Pwm(m.left_motor_enabled ? m.left_motor_speed : 0.0,
                                        m.right_motor_enabled ? m.right_motor_speed : 0.0);
        return true;
      });
  add(mbot_w23::mbot_wheel_ctrl_t::getHash(), "mbot_wheel_ctrl_t", kW23,
      [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
        mbot_w23::mbot_wheel_ctrl_t m{};
        if (!DecodeExact(d, n, &m, err)) return false;
        ev->kind = EventKind::kMotorCommand;
        ev->stamp_us = m.utime;
        ev->payload = MotorCommand::Pwm(m.left_motor_pwm, m.right_motor_pwm);
        return true;
      });
  add(mbot_w23::mbot_state_t::getHash(), "mbot_state_t", kW23,
      [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
        mbot_w23::mbot_state_t m{};
        if (!DecodeExact(d, n, &m, err)) return false;
        ev->kind = EventKind::kOther;
        ev->stamp_us = m.utime;
        ev->payload = motion::Pose2D{m.x, m.y, m.theta};
        return true;
      });

  add(mbot_legacy::occupancy_grid_t::getHash(), "occupancy_grid_t", kLegacy,
      [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
        return DecodeGrid<mbot_legacy::occupancy_grid_t>(d, n, 36, ev, err);
      });
  add(mbot_legacy::occupancy_grid_t::getHash(), "occupancy_grid_t", kCurrent, nullptr);
  add(mbot_w23::occupancy_grid_t::getHash(), "occupancy_grid_t", kW23,
      [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
        // num_cells is followed by slam_mode and a string before the cells: check against the rest.
        if (!CheckString(d, n, 44, "slam_map_location", err)) return false;
        return DecodeGrid<mbot_w23::occupancy_grid_t>(d, n, 36, ev, err);
      });

  add(mbot_legacy::particles_t::getHash(), "particles_t", kLegacy,
      Other<mbot_legacy::particles_t>(16, 48, "num_particles"));
  add(mbot_legacy::particles_t::getHash(), "particles_t", kW23, nullptr);
  add(mbot_legacy::particles_t::getHash(), "particles_t", kCurrent, nullptr);
  add(mbot_legacy::robot_path_t::getHash(), "robot_path_t", kLegacy,
      [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
        if (!CheckCount(d, n, 16, 20, "path_length", err)) return false;
        mbot_legacy::robot_path_t m{};
        if (!DecodeExact(d, n, &m, err)) return false;
        Path path;
        for (const auto& p : m.path) {
          if (!Finite(p.x, p.y, p.theta)) {
            *err = "non-finite pose in the path";
            return false;
          }
          path.poses.push_back({p.x, p.y, p.theta});
        }
        ev->kind = EventKind::kPath;
        ev->stamp_us = m.utime;
        ev->payload = std::move(path);
        return true;
      });
  add(mbot_legacy::robot_path_t::getHash(), "path2D_t", kCurrent, nullptr);
  add(mbot_legacy::timestamp_t::getHash(), "timestamp_t", kLegacy, Other<mbot_legacy::timestamp_t>());
  add(mbot_legacy::timestamp_t::getHash(), "timestamp_t", kW23, nullptr);
  add(mbot_legacy::timestamp_t::getHash(), "timestamp_t", kCurrent, nullptr);
  add(mbot_legacy::message_received_t::getHash(), "message_received_t", kLegacy,
      OtherWithString<mbot_legacy::message_received_t>(24, "channel"));
  add(mbot_legacy::message_received_t::getHash(), "mbot_message_received_t", kCurrent, nullptr);
  add(mbot_legacy::exploration_status_t::getHash(), "exploration_status_t", kLegacy,
      Other<mbot_legacy::exploration_status_t>());
  add(mbot_legacy::exploration_status_t::getHash(), "exploration_status_t", kW23, nullptr);
  add(mbot_lcm_msgs::exploration_status_t::getHash(), "exploration_status_t", kCurrent,
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
        ev->payload =
            mission::MissionStatus{incomplete ? mission::MissionState::kIncomplete : kExplorationStates[m.state],
                                   kExplorationStatuses[m.status]};
        return true;
      });
  add(mbot_lcm_msgs::slam_status_t::getHash(), "slam_status_t", kCurrent,
      OtherWithString<mbot_lcm_msgs::slam_status_t>(20, "map_path"));
  add(mbot_lcm_msgs::mbot_slam_reset_t::getHash(), "mbot_slam_reset_t", kCurrent,
      OtherWithString<mbot_lcm_msgs::mbot_slam_reset_t>(20, "slam_map_location"));
  add(mbot_w23::mbot_system_reset_t::getHash(), "mbot_system_reset_t", kW23, nullptr);
  add(mbot_lcm_msgs::mbot_apriltag_array_t::getHash(), "mbot_apriltag_array_t", kCurrent,
      [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
        // array_size follows utime; each detection is an int32 id and a pose3D_t (8 + 3·4 + 3·4 + 4·4).
        if (!CheckCount(d, n, 16, 4 + 48, "array_size", err)) return false;
        mbot_lcm_msgs::mbot_apriltag_array_t m{};
        if (!DecodeExact(d, n, &m, err)) return false;
        TagSightings out;
        for (const auto& t : m.detections) {
          const auto& p = t.pose;
          const double q[4] = {p.angles_quat[0], p.angles_quat[1], p.angles_quat[2], p.angles_quat[3]};
          const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
          if (!Finite(p.x, p.y, p.z) || !std::isfinite(norm) || std::abs(norm - 1.0) > 1e-3) {
            *err = "tag " + std::to_string(t.tag_id) + ": non-finite position or a quaternion that is not of unit norm";
            return false;
          }
          // The botlab's publisher: millimetres; quaternion x, y, z, w.
          out.tags.push_back(
              {t.tag_id, p.x * 1e-3, p.y * 1e-3, p.z * 1e-3, q[3] / norm, q[0] / norm, q[1] / norm, q[2] / norm});
        }
        ev->kind = EventKind::kTagSightings;
        ev->stamp_us = m.utime;
        ev->payload = std::move(out);
        return true;
      });
  // mbot_nav's own types (lcmtypes/mbot_nav): the forklift and camera frames.
  const std::string kOwn = "mbot_nav";
  add(mbot_nav_msgs::mbot_forklift_cmd_t::getHash(), "mbot_forklift_cmd_t", kOwn,
      [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
        mbot_nav_msgs::mbot_forklift_cmd_t m{};
        if (!DecodeExact(d, n, &m, err)) return false;
        if (!std::isfinite(m.height)) {
          *err = "a height that is not a finite number";
          return false;
        }
        ev->kind = EventKind::kForkliftCommand;
        ev->stamp_us = m.utime;
        ev->payload = ForkliftCommand{m.height};
        return true;
      });
  add(mbot_nav_msgs::mbot_forklift_status_t::getHash(), "mbot_forklift_status_t", kOwn,
      [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
        mbot_nav_msgs::mbot_forklift_status_t m{};
        if (!DecodeExact(d, n, &m, err)) return false;
        if (!std::isfinite(m.height) || !std::isfinite(m.target) || m.crate_id < -1) {
          *err = "a height or target that is not finite, or a crate id below -1";
          return false;
        }
        ev->kind = EventKind::kForkliftStatus;
        ev->stamp_us = m.utime;
        ev->payload = ForkliftStatus{m.height, m.target, m.crate_id, m.carrying != 0};
        return true;
      });
  add(mbot_nav_msgs::mbot_image_t::getHash(), "mbot_image_t", kOwn,
      [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
        // num_bytes follows utime, width and height.
        if (!CheckCount(d, n, 24, 1, "num_bytes", err)) return false;
        mbot_nav_msgs::mbot_image_t m{};
        if (!DecodeExact(d, n, &m, err)) return false;
        if (m.width < 1 || m.height < 1 || m.width > 8192 || m.height > 8192 ||
            static_cast<int64_t>(m.width) * m.height != m.num_bytes) {
          *err = "a " + std::to_string(m.width) + " x " + std::to_string(m.height) + " image with " +
                 std::to_string(m.num_bytes) + " bytes";
          return false;
        }
        CameraFrame f;
        f.width = m.width, f.height = m.height;
        f.pixels = std::make_shared<const std::vector<uint8_t>>(m.data.begin(), m.data.end());
        f.name = "mbot_image_t";
        ev->kind = EventKind::kCameraFrame;
        ev->stamp_us = m.utime;
        ev->payload = std::move(f);
        return true;
      });
  return t;
}

const std::map<int64_t, Entry>& Table() {
  static const std::map<int64_t, Entry> table = BuildTable();
  return table;
}

}  // namespace

int64_t Fingerprint(const uint8_t* data, size_t size) {
  if (size < 8) return 0;
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | data[i];
  return static_cast<int64_t>(v);
}

const TypeInfo* LookUp(int64_t fingerprint) {
  auto it = Table().find(fingerprint);
  return it == Table().end() ? nullptr : &it->second.info;
}

bool Decode(const std::string& channel, const uint8_t* data, size_t size, const ChannelRoles& roles, Event* event,
            std::string* error) {
  auto it = Table().find(Fingerprint(data, size));
  if (it == Table().end()) {
    *error = "unknown fingerprint";
    return false;
  }
  return it->second.decode(channel, data, size, roles, event, error);
}

std::vector<std::pair<int64_t, TypeInfo>> KnownTypes() {
  std::vector<std::pair<int64_t, TypeInfo>> out;
  for (const auto& [hash, e] : Table()) out.emplace_back(hash, e.info);
  return out;
}

namespace {

template <typename T>
void EncodeMessage(const T& m, std::vector<uint8_t>* out) {
  out->resize(static_cast<size_t>(m.getEncodedSize()));
  m.encode(out->data(), 0, static_cast<int>(out->size()));
}

}  // namespace

bool Encode(const Event& ev, std::vector<uint8_t>* out) {
  out->clear();
  switch (ev.kind) {
    case EventKind::kLidar: {
      const auto& scan = std::get<LidarScan>(ev.payload);
      mbot_legacy::lidar_t m{};
      m.utime = ev.stamp_us;
      m.num_ranges = static_cast<int32_t>(scan.ranges_m.size());
      m.ranges = scan.ranges_m;
      m.thetas.resize(scan.angles_rad.size());
      for (size_t i = 0; i < scan.angles_rad.size(); ++i) m.thetas[i] = -scan.angles_rad[i];  // clockwise on the wire
      m.times = scan.beam_times_us;
      m.times.resize(scan.ranges_m.size(), ev.stamp_us);
      m.intensities = scan.intensities;
      m.intensities.resize(scan.ranges_m.size(), 0.0f);
      if (m.thetas.size() != scan.ranges_m.size()) return false;
      EncodeMessage(m, out);
      return true;
    }
    case EventKind::kOdometry:
    case EventKind::kGroundTruth:
    case EventKind::kReferencePose:
    case EventKind::kPoseEstimate:
    case EventKind::kCollision: {
      const auto& p = std::get<motion::Pose2D>(ev.payload);
      mbot_lcm_msgs::pose2D_t m{};
      m.utime = ev.stamp_us;
      m.x = static_cast<float>(p.x), m.y = static_cast<float>(p.y), m.theta = static_cast<float>(p.theta);
      EncodeMessage(m, out);
      return true;
    }
    case EventKind::kEncoders: {
      const auto& e = std::get<EncoderTicks>(ev.payload);
      mbot_lcm_msgs::mbot_encoders_t m{};
      m.utime = ev.stamp_us;
      m.ticks[0] = e.left_ticks, m.ticks[1] = e.right_ticks;
      m.delta_ticks[0] = e.left_delta, m.delta_ticks[1] = e.right_delta;
      m.delta_time = static_cast<int32_t>(e.delta_time_us);
      EncodeMessage(m, out);
      return true;
    }
    case EventKind::kImu: {
      const auto& imu = std::get<Imu>(ev.payload);
      mbot_lcm_msgs::mbot_imu_t m{};
      m.utime = ev.stamp_us;
      for (int i = 0; i < 3; ++i) {
        m.gyro[i] = static_cast<float>(imu.gyro_rad_s[i]);
        m.accel[i] = static_cast<float>(imu.accel_m_s2[i]);
        m.angles_rpy[i] = static_cast<float>(imu.angles_rpy_rad[i]);
      }
      EncodeMessage(m, out);
      return true;
    }
    case EventKind::kMotorCommand: {
      const auto& c = std::get<MotorCommand>(ev.payload);
      if (c.kind == MotorCommand::Kind::kVelocity) {
        mbot_lcm_msgs::twist2D_t m{};
        m.utime = ev.stamp_us;
        m.vx = static_cast<float>(c.velocity.v_m_s), m.wz = static_cast<float>(c.velocity.w_rad_s);
        EncodeMessage(m, out);
      } else {
        mbot_lcm_msgs::mbot_motor_pwm_t m{};
        m.utime = ev.stamp_us;
        m.pwm[0] = static_cast<float>(c.left_duty), m.pwm[1] = static_cast<float>(c.right_duty);
        EncodeMessage(m, out);
      }
      return true;
    }
    case EventKind::kWheelSpeed: {
      const auto& w = std::get<WheelSpeeds>(ev.payload);
      mbot_lcm_msgs::mbot_motor_vel_t m{};
      m.utime = ev.stamp_us;
      m.velocity[0] = static_cast<float>(w.left_rad_s), m.velocity[1] = static_cast<float>(w.right_rad_s);
      EncodeMessage(m, out);
      return true;
    }
    case EventKind::kMap: {
      const auto& grid = std::get<std::shared_ptr<const mapping::OccupancyGrid>>(ev.payload);
      if (!grid) return false;
      mbot_legacy::occupancy_grid_t m{};  // the 2023+ occupancy_grid_t has the same layout and hash
      m.utime = ev.stamp_us;
      m.origin_x = static_cast<float>(grid->origin_x()), m.origin_y = static_cast<float>(grid->origin_y());
      m.meters_per_cell = static_cast<float>(grid->resolution());
      m.width = grid->width(), m.height = grid->height();
      m.num_cells = static_cast<int32_t>(grid->cells().size());
      m.cells.assign(grid->cells().begin(), grid->cells().end());
      EncodeMessage(m, out);
      return true;
    }
    case EventKind::kPath: {
      mbot_legacy::robot_path_t m{};  // = 2023+ path2D_t
      m.utime = ev.stamp_us;
      for (const motion::Pose2D& p : std::get<Path>(ev.payload).poses) {
        m.path.push_back({ev.stamp_us, static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.theta)});
      }
      m.path_length = static_cast<int32_t>(m.path.size());
      EncodeMessage(m, out);
      return true;
    }
    case EventKind::kTagSightings: {
      // As the botlab's publisher sends it: the camera frame in millimetres, roll-pitch-yaw in
      // degrees (its XYZ convention), the quaternion as x, y, z, w.
      mbot_lcm_msgs::mbot_apriltag_array_t m{};
      m.utime = ev.stamp_us;
      for (const TagSighting& s : std::get<TagSightings>(ev.payload).tags) {
        mbot_lcm_msgs::mbot_apriltag_t t{};
        t.tag_id = s.id;
        t.pose.utime = ev.stamp_us;
        t.pose.x = static_cast<float>(s.x_m * 1e3), t.pose.y = static_cast<float>(s.y_m * 1e3);
        t.pose.z = static_cast<float>(s.z_m * 1e3);
        const double w = s.qw, x = s.qx, y = s.qy, z = s.qz;  // rotation matrix entries from the quaternion
        const double r00 = 1 - 2 * (y * y + z * z), r10 = 2 * (x * y + w * z), r20 = 2 * (x * z - w * y);
        const double r21 = 2 * (y * z + w * x), r22 = 1 - 2 * (x * x + y * y);
        const double deg = 180.0 / M_PI;
        t.pose.angles_rpy[0] = static_cast<float>(std::atan2(r21, r22) * deg);
        t.pose.angles_rpy[1] = static_cast<float>(std::atan2(-r20, std::hypot(r00, r10)) * deg);
        t.pose.angles_rpy[2] = static_cast<float>(std::atan2(r10, r00) * deg);
        t.pose.angles_quat[0] = static_cast<float>(x), t.pose.angles_quat[1] = static_cast<float>(y);
        t.pose.angles_quat[2] = static_cast<float>(z), t.pose.angles_quat[3] = static_cast<float>(w);
        m.detections.push_back(t);
      }
      m.array_size = static_cast<int32_t>(m.detections.size());
      EncodeMessage(m, out);
      return true;
    }
    case EventKind::kForkliftCommand: {
      mbot_nav_msgs::mbot_forklift_cmd_t m{};
      m.utime = ev.stamp_us;
      m.height = static_cast<float>(std::get<ForkliftCommand>(ev.payload).height_m);
      EncodeMessage(m, out);
      return true;
    }
    case EventKind::kForkliftStatus: {
      const auto& f = std::get<ForkliftStatus>(ev.payload);
      mbot_nav_msgs::mbot_forklift_status_t m{};
      m.utime = ev.stamp_us;
      m.height = static_cast<float>(f.height_m), m.target = static_cast<float>(f.target_m);
      m.crate_id = f.crate_id;
      m.carrying = f.carrying;
      EncodeMessage(m, out);
      return true;
    }
    case EventKind::kCameraFrame: {
      const auto& f = std::get<CameraFrame>(ev.payload);
      if (!f.pixels || f.pixels->size() != static_cast<size_t>(f.width) * f.height) return false;
      mbot_nav_msgs::mbot_image_t m{};
      m.utime = ev.stamp_us;
      m.width = f.width, m.height = f.height;
      m.num_bytes = static_cast<int32_t>(f.pixels->size());
      m.data.assign(f.pixels->begin(), f.pixels->end());
      EncodeMessage(m, out);
      return true;
    }
    case EventKind::kParticles: {
      const Particles& p = std::get<Particles>(ev.payload);
      mbot_legacy::particles_t m{};  // = 2023+ particles_t
      m.utime = ev.stamp_us;
      for (size_t i = 0; i < p.poses.size(); ++i) {
        mbot_legacy::particle_t q{};
        q.pose = {ev.stamp_us, static_cast<float>(p.poses[i].x), static_cast<float>(p.poses[i].y),
                  static_cast<float>(p.poses[i].theta)};
        q.parent_pose = q.pose;
        q.weight = i < p.weights.size() ? p.weights[i] : 0.0;
        m.particles.push_back(q);
      }
      m.num_particles = static_cast<int32_t>(m.particles.size());
      EncodeMessage(m, out);
      return true;
    }
    case EventKind::kSlamStatus: {
      // SLAM's status as slam_status_t's mode (its own states — localizing, localized, lost — have
      // no field there).
      const auto& st = std::get<mapping::SlamStatus>(ev.payload);
      mbot_lcm_msgs::slam_status_t m{};
      m.utime = ev.stamp_us;
      m.slam_mode = st.mode == mapping::SlamMode::kMappingOnly    ? 0
                    : st.mode == mapping::SlamMode::kActionOnly   ? 1
                    : st.mode == mapping::SlamMode::kLocalization ? 2
                                                                  : 3;
      EncodeMessage(m, out);
      return true;
    }
    case EventKind::kMissionStatus: {
      // A task's state as the nearest exploration_status_t state (a state of its own, e.g. driving
      // or lifting, is one in progress).
      const auto& st = std::get<mission::MissionStatus>(ev.payload);
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
      if (st.state == mission::MissionState::kIncomplete) {  // home, frontiers left: completed, not successfully
        m.state = X::STATE_COMPLETED_EXPLORATION;
        m.status = X::STATUS_FAILED;
      }
      EncodeMessage(m, out);
      return true;
    }
    default: return false;
  }
}

}  // namespace mbot::drivers::lcm_adapter
