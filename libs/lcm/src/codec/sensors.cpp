// The sensor and actuator family: lidar_t, the encoder, IMU and motor messages of every generation.
#include "codec.hpp"
#include "maebot/maebot_encoders_t.hpp"
#include "maebot/maebot_imu_t.hpp"
#include "maebot/maebot_motor_command_t.hpp"
#include "mbot_lcm_msgs/mbot_encoders_t.hpp"
#include "mbot_lcm_msgs/mbot_imu_t.hpp"
#include "mbot_lcm_msgs/mbot_motor_pwm_t.hpp"
#include "mbot_lcm_msgs/mbot_motor_vel_t.hpp"
#include "mbot_lcm_msgs/twist2D_t.hpp"
#include "mbot_legacy/lidar_t.hpp"
#include "mbot_legacy/mbot_encoder_t.hpp"
#include "mbot_legacy/mbot_imu_t.hpp"
#include "mbot_legacy/mbot_motor_command_t.hpp"
#include "mbot_w23/mbot_state_t.hpp"
#include "mbot_w23/mbot_wheel_ctrl_t.hpp"

namespace mbot::lcmio::lcm_adapter {

namespace {

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

}  // namespace

void AddSensorTypes(TypeTable& t) {
  Decoder lidar = [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
    return DecodeLidar<mbot_legacy::lidar_t>(d, n, ev, err);
  };
  t.Add(mbot_legacy::lidar_t::getHash(), "lidar_t", kLegacy, lidar);
  t.Add(mbot_legacy::lidar_t::getHash(), "lidar_t", kW23, lidar);
  t.Add(mbot_legacy::lidar_t::getHash(), "lidar_t", kCurrent, lidar);
  t.Add(mbot_legacy::lidar_t::getHash(), "rplidar_laser_t", kMaebot, lidar);

  t.Add(mbot_legacy::mbot_encoder_t::getHash(), "mbot_encoder_t", kLegacy,
        [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
          mbot_legacy::mbot_encoder_t m{};
          if (!DecodeExact(d, n, &m, err)) return false;
          ev->kind = EventKind::kEncoders;
          ev->stamp_us = m.utime;
          ev->payload = EncoderTicks{m.leftticks, m.rightticks, m.left_delta, m.right_delta, 0};
          return true;
        });
  t.Add(mbot_legacy::mbot_encoder_t::getHash(), "mbot_encoder_t", kW23, nullptr);
  t.Add(mbot_lcm_msgs::mbot_encoders_t::getHash(), "mbot_encoders_t", kCurrent,
        [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
          mbot_lcm_msgs::mbot_encoders_t m{};
          if (!DecodeExact(d, n, &m, err)) return false;
          ev->kind = EventKind::kEncoders;
          ev->stamp_us = m.utime;
          ev->payload = EncoderTicks{m.ticks[0], m.ticks[1], m.delta_ticks[0], m.delta_ticks[1], m.delta_time};
          return true;
        });
  t.Add(maebot::maebot_encoders_t::getHash(), "maebot_encoders_t", kMaebot,
        [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
          maebot::maebot_encoders_t m{};
          if (!DecodeExact(d, n, &m, err)) return false;
          ev->kind = EventKind::kEncoders;
          ev->stamp_us = m.utime;
          ev->payload = EncoderTicks{m.left_ticks_total, m.right_ticks_total, 0, 0, 0};
          return true;
        });

  t.Add(mbot_legacy::mbot_imu_t::getHash(), "mbot_imu_t", kLegacy,
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
  t.Add(mbot_legacy::mbot_imu_t::getHash(), "mbot_imu_t", kW23, nullptr);
  t.Add(mbot_lcm_msgs::mbot_imu_t::getHash(), "mbot_imu_t", kCurrent,
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
  t.Add(maebot::maebot_imu_t::getHash(), "maebot_imu_t", kMaebot,
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

  t.Add(mbot_legacy::mbot_motor_command_t::getHash(), "mbot_motor_command_t", kLegacy,
        [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
          mbot_legacy::mbot_motor_command_t m{};
          if (!DecodeExact(d, n, &m, err)) return false;
          ev->kind = EventKind::kMotorCommand;
          ev->stamp_us = m.utime;
          ev->payload = MotorCommand::Velocity(m.trans_v, m.angular_v);
          return true;
        });
  t.Add(mbot_legacy::mbot_motor_command_t::getHash(), "mbot_motor_command_t", kW23, nullptr);
  t.Add(mbot_lcm_msgs::twist2D_t::getHash(), "twist2D_t", kCurrent,
        [](const std::string& ch, const uint8_t* d, size_t n, const ChannelRoles& roles, Event* ev, std::string* err) {
          mbot_lcm_msgs::twist2D_t m{};
          if (!DecodeExact(d, n, &m, err)) return false;
          ev->stamp_us = m.utime;
          ev->kind = In(roles.velocity_command, ch) ? EventKind::kMotorCommand : EventKind::kOther;
          ev->payload = MotorCommand::Velocity(m.vx, m.wz);
          return true;
        });
  t.Add(mbot_lcm_msgs::mbot_motor_pwm_t::getHash(), "mbot_motor_pwm_t", kCurrent,
        [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
          mbot_lcm_msgs::mbot_motor_pwm_t m{};
          if (!DecodeExact(d, n, &m, err)) return false;
          ev->kind = EventKind::kMotorCommand;
          ev->stamp_us = m.utime;
          ev->payload = MotorCommand::Pwm(m.pwm[0], m.pwm[1]);
          return true;
        });
  t.Add(mbot_lcm_msgs::mbot_motor_vel_t::getHash(), "mbot_motor_vel_t", kCurrent,
        [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
          mbot_lcm_msgs::mbot_motor_vel_t m{};
          if (!DecodeExact(d, n, &m, err)) return false;
          ev->kind = EventKind::kWheelSpeed;  // measured wheel speeds, not a command
          ev->stamp_us = m.utime;
          ev->payload = WheelSpeeds{m.velocity[0], m.velocity[1]};
          return true;
        });
  t.Add(maebot::maebot_motor_command_t::getHash(), "maebot_motor_command_t", kMaebot,
        [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
          maebot::maebot_motor_command_t m{};
          if (!DecodeExact(d, n, &m, err)) return false;
          ev->kind = EventKind::kMotorCommand;
          ev->stamp_us = m.utime;
          ev->payload = MotorCommand::Pwm(m.left_motor_enabled ? m.left_motor_speed : 0.0,
                                          m.right_motor_enabled ? m.right_motor_speed : 0.0);
          return true;
        });
  t.Add(mbot_w23::mbot_wheel_ctrl_t::getHash(), "mbot_wheel_ctrl_t", kW23,
        [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
          mbot_w23::mbot_wheel_ctrl_t m{};
          if (!DecodeExact(d, n, &m, err)) return false;
          ev->kind = EventKind::kMotorCommand;
          ev->stamp_us = m.utime;
          ev->payload = MotorCommand::Pwm(m.left_motor_pwm, m.right_motor_pwm);
          return true;
        });
  t.Add(mbot_w23::mbot_state_t::getHash(), "mbot_state_t", kW23,
        [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
          mbot_w23::mbot_state_t m{};
          if (!DecodeExact(d, n, &m, err)) return false;
          ev->kind = EventKind::kOther;
          ev->stamp_us = m.utime;
          ev->payload = msgs::Pose2D{m.x, m.y, m.theta};
          return true;
        });
}

bool Encoder::Lidar(const Event& ev, const LidarScan& scan) {
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
  return Put(m);
}

bool Encoder::Encoders(const Event& ev, const EncoderTicks& e) {
  mbot_lcm_msgs::mbot_encoders_t m{};
  m.utime = ev.stamp_us;
  m.ticks[0] = e.left_ticks, m.ticks[1] = e.right_ticks;
  m.delta_ticks[0] = e.left_delta, m.delta_ticks[1] = e.right_delta;
  m.delta_time = static_cast<int32_t>(e.delta_time_us);
  return Put(m);
}

bool Encoder::ImuReading(const Event& ev, const Imu& imu) {
  mbot_lcm_msgs::mbot_imu_t m{};
  m.utime = ev.stamp_us;
  for (int i = 0; i < 3; ++i) {
    m.gyro[i] = static_cast<float>(imu.gyro_rad_s[i]);
    m.accel[i] = static_cast<float>(imu.accel_m_s2[i]);
    m.angles_rpy[i] = static_cast<float>(imu.angles_rpy_rad[i]);
  }
  return Put(m);
}

bool Encoder::Motors(const Event& ev, const MotorCommand& c) {
  if (c.kind == MotorCommand::Kind::kVelocity) {
    mbot_lcm_msgs::twist2D_t m{};
    m.utime = ev.stamp_us;
    m.vx = static_cast<float>(c.velocity.v_m_s), m.wz = static_cast<float>(c.velocity.w_rad_s);
    return Put(m);
  }
  mbot_lcm_msgs::mbot_motor_pwm_t m{};
  m.utime = ev.stamp_us;
  m.pwm[0] = static_cast<float>(c.left_duty), m.pwm[1] = static_cast<float>(c.right_duty);
  return Put(m);
}

bool Encoder::Wheels(const Event& ev, const WheelSpeeds& w) {
  mbot_lcm_msgs::mbot_motor_vel_t m{};
  m.utime = ev.stamp_us;
  m.velocity[0] = static_cast<float>(w.left_rad_s), m.velocity[1] = static_cast<float>(w.right_rad_s);
  return Put(m);
}

}  // namespace mbot::lcmio::lcm_adapter
