// Round trips through the LCM edge (lcm_adapter::Encode → Decode, the current mbot_lcm_msgs types):
// what the stack publishes comes back as the same typed event.
#include "lcm_messages.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "maebot/maebot_encoders_t.hpp"
#include "mbot_lcm_msgs/mbot_apriltag_array_t.hpp"
#include "maebot/maebot_motor_command_t.hpp"
#include "mbot_legacy/mbot_encoder_t.hpp"
#include "mbot_legacy/mbot_imu_t.hpp"
#include "mbot_legacy/mbot_motor_command_t.hpp"
#include "mbot_legacy/pose_xyt_t.hpp"
#include "mbot_w23/mbot_wheel_ctrl_t.hpp"
#include "mbot_w23/occupancy_grid_t.hpp"

namespace mbot::lcmio {

using namespace msgs;  // the event vocabulary
namespace {

Event RoundTrip(const Event& in) {
  std::vector<uint8_t> bytes;
  EXPECT_TRUE(lcm_adapter::Encode(in, &bytes)) << in.channel;
  Event out;
  out.channel = in.channel;
  std::string error;
  EXPECT_TRUE(lcm_adapter::Decode(in.channel, bytes.data(), bytes.size(), ChannelRoles{}, &out, &error)) << error;
  EXPECT_EQ(out.stamp_us, in.stamp_us);
  return out;
}

// Tag sightings go out as the botlab's publisher sends them (millimetres, degrees, quaternion
// x y z w) and come back as the same metres and unit quaternion.
TEST(LcmMessages, TagSightingsTravelAsTheBotlabsAprilTagArray) {
  Event in;
  in.kind = EventKind::kTagSightings;
  in.channel = "MBOT_APRILTAG_ARRAY";
  in.stamp_us = 1'700'000'000'000'000;
  const double h = std::sqrt(0.5);  // 90° about the camera's x axis
  in.payload = TagSightings{{{3, 0.1, -0.05, 0.75, h, h, 0.0, 0.0}, {12, -0.2, 0.0, 1.5, 1.0, 0.0, 0.0, 0.0}}};
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(lcm_adapter::Encode(in, &bytes));
  mbot_lcm_msgs::mbot_apriltag_array_t wire;
  ASSERT_EQ(wire.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  ASSERT_EQ(wire.array_size, 2);
  EXPECT_EQ(wire.detections[0].tag_id, 3);
  EXPECT_FLOAT_EQ(wire.detections[0].pose.x, 100.0f);  // mm
  EXPECT_FLOAT_EQ(wire.detections[0].pose.z, 750.0f);
  EXPECT_NEAR(wire.detections[0].pose.angles_rpy[0], 90.0f, 1e-4);  // degrees
  EXPECT_NEAR(wire.detections[0].pose.angles_quat[0], h, 1e-6);     // x first, w last
  EXPECT_NEAR(wire.detections[0].pose.angles_quat[3], h, 1e-6);
  const Event out = RoundTrip(in);
  ASSERT_EQ(out.kind, EventKind::kTagSightings);
  const auto& tags = std::get<TagSightings>(out.payload).tags;
  ASSERT_EQ(tags.size(), 2u);
  EXPECT_EQ(tags[1].id, 12);
  EXPECT_NEAR(tags[0].x_m, 0.1, 1e-6);
  EXPECT_NEAR(tags[1].z_m, 1.5, 1e-6);
  EXPECT_NEAR(tags[0].qw, h, 1e-6);
  EXPECT_NEAR(tags[0].qx, h, 1e-6);
  // A count that disagrees with the payload, and a quaternion that is not a rotation, are rejected.
  std::string error;
  Event ev;
  std::vector<uint8_t> bad = bytes;
  bad[19] = 3;  // array_size (big-endian int32 at offset 16) 2 → 3
  EXPECT_FALSE(lcm_adapter::Decode("MBOT_APRILTAG_ARRAY", bad.data(), bad.size(), ChannelRoles{}, &ev, &error));
  EXPECT_NE(error.find("array_size"), std::string::npos) << error;
  wire.detections[1].pose.angles_quat[3] = 3.0f;
  bad.resize(static_cast<size_t>(wire.getEncodedSize()));
  wire.encode(bad.data(), 0, static_cast<int>(bad.size()));
  EXPECT_FALSE(lcm_adapter::Decode("MBOT_APRILTAG_ARRAY", bad.data(), bad.size(), ChannelRoles{}, &ev, &error));
  EXPECT_NE(error.find("tag 12"), std::string::npos) << error;
}

// mbot_nav's own types: the forklift's command and status, and camera frames.
TEST(LcmMessages, ForkliftAndCameraFramesRoundTrip) {
  const Event cmd = RoundTrip(Event{0, 7, "MBOT_FORKLIFT_CMD", EventKind::kForkliftCommand, ForkliftCommand{0.125}});
  ASSERT_EQ(cmd.kind, EventKind::kForkliftCommand);
  EXPECT_FLOAT_EQ(std::get<ForkliftCommand>(cmd.payload).height_m, 0.125f);
  const Event st =
      RoundTrip(Event{0, 8, "MBOT_FORKLIFT_STATUS", EventKind::kForkliftStatus, ForkliftStatus{0.05, 0.13, 12, true}});
  ASSERT_EQ(st.kind, EventKind::kForkliftStatus);
  const auto& f = std::get<ForkliftStatus>(st.payload);
  EXPECT_FLOAT_EQ(f.height_m, 0.05f);
  EXPECT_FLOAT_EQ(f.target_m, 0.13f);
  EXPECT_EQ(f.crate_id, 12);
  EXPECT_TRUE(f.carrying);

  CameraFrame frame;
  frame.width = 4, frame.height = 3;
  frame.pixels =
      std::make_shared<const std::vector<uint8_t>>(std::vector<uint8_t>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 255});
  const Event img = RoundTrip(Event{0, 9, "CAMERA", EventKind::kCameraFrame, frame});
  ASSERT_EQ(img.kind, EventKind::kCameraFrame);
  const auto& g = std::get<CameraFrame>(img.payload);
  EXPECT_EQ(g.width, 4);
  EXPECT_EQ(g.height, 3);
  ASSERT_TRUE(g.pixels);
  EXPECT_EQ(*g.pixels, *frame.pixels);
  // A size that disagrees with the bytes is rejected, naming the sizes.
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(lcm_adapter::Encode(Event{0, 9, "CAMERA", EventKind::kCameraFrame, frame}, &bytes));
  bytes[19] = 5;  // width (big-endian int32 after the hash and utime, at offset 16) 4 → 5
  Event ev;
  std::string error;
  EXPECT_FALSE(lcm_adapter::Decode("CAMERA", bytes.data(), bytes.size(), ChannelRoles{}, &ev, &error));
  EXPECT_NE(error.find("5 x 3 image with 12 bytes"), std::string::npos) << error;
}

TEST(LcmMessages, VelocityCommandRoundTrips) {
  const Event out =
      RoundTrip(Event{0, 123, "MBOT_VEL_CMD", EventKind::kMotorCommand, MotorCommand::Velocity(0.25, -1.5)});
  ASSERT_EQ(out.kind, EventKind::kMotorCommand);
  const auto& c = std::get<MotorCommand>(out.payload);
  EXPECT_EQ(c.kind, MotorCommand::Kind::kVelocity);
  EXPECT_FLOAT_EQ(c.velocity.v_m_s, 0.25f);
  EXPECT_FLOAT_EQ(c.velocity.w_rad_s, -1.5f);
}

TEST(LcmMessages, PwmAndMeasuredWheelSpeedsAreDistinctTypes) {
  const Event pwm = RoundTrip(Event{0, 5, "MBOT_MOTOR_PWM", EventKind::kMotorCommand, MotorCommand::Pwm(0.3, -0.2)});
  ASSERT_EQ(pwm.kind, EventKind::kMotorCommand);
  EXPECT_EQ(std::get<MotorCommand>(pwm.payload).kind, MotorCommand::Kind::kPwm);
  EXPECT_FLOAT_EQ(std::get<MotorCommand>(pwm.payload).left_duty, 0.3f);
  EXPECT_FLOAT_EQ(std::get<MotorCommand>(pwm.payload).right_duty, -0.2f);
  const Event speeds = RoundTrip(Event{0, 6, "MBOT_MOTOR_VEL", EventKind::kWheelSpeed, WheelSpeeds{4.5, -3.25}});
  ASSERT_EQ(speeds.kind, EventKind::kWheelSpeed);
  EXPECT_FLOAT_EQ(std::get<WheelSpeeds>(speeds.payload).left_rad_s, 4.5f);
  EXPECT_FLOAT_EQ(std::get<WheelSpeeds>(speeds.payload).right_rad_s, -3.25f);
}

// exploration_status_t has five states: the mission's own in-progress states (driving, lifting …)
// go out as exploring; the rest keep their meaning.
TEST(LcmMessages, MissionStatesGoOutAsTheBotlabExplorationStates) {
  using msgs::MissionState;
  const std::pair<MissionState, MissionState> cases[] = {{MissionState::kInitializing, MissionState::kInitializing},
                                                         {MissionState::kExploring, MissionState::kExploring},
                                                         {MissionState::kReturningHome, MissionState::kReturningHome},
                                                         {MissionState::kCompleted, MissionState::kCompleted},
                                                         {MissionState::kFailed, MissionState::kFailed},
                                                         {MissionState::kDriving, MissionState::kExploring},
                                                         {MissionState::kLifting, MissionState::kExploring}};
  for (const auto& [sent, received] : cases) {
    const Event out =
        RoundTrip(Event{0, 9, "EXPLORATION_STATUS", EventKind::kMissionStatus, msgs::MissionStatus{sent, "x"}});
    ASSERT_EQ(out.kind, EventKind::kMissionStatus);
    EXPECT_EQ(std::get<msgs::MissionStatus>(out.payload).state, received) << msgs::ToString(sent);
  }
}

TEST(LcmMessages, SlamStatusCarriesTheMode) {
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(
      lcm_adapter::Encode(Event{0, 1, "SLAM_STATUS", EventKind::kSlamStatus,
                                msgs::SlamStatus{msgs::SlamState::kLocalized, msgs::SlamMode::kLocalization, 0.1}},
                          &bytes));
  const lcm_adapter::TypeInfo* type = lcm_adapter::LookUp(lcm_adapter::Fingerprint(bytes.data(), bytes.size()));
  ASSERT_NE(type, nullptr);
  EXPECT_EQ(type->type, "slam_status_t");
}

// Found by fuzz_lcm_messages: a string length of INT32_MIN made lcm-gen's decoder compute
// `length - 1` (signed overflow); 0 asked std::string for SIZE_MAX bytes. Both are rejected first.
TEST(LcmMessages, StringLengthsAreCheckedBeforeLcmGenDecodes) {
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(
      lcm_adapter::Encode(Event{0, 1, "SLAM_STATUS", EventKind::kSlamStatus,
                                msgs::SlamStatus{msgs::SlamState::kLocalized, msgs::SlamMode::kLocalization, 0.1}},
                          &bytes));
  ASSERT_GE(bytes.size(), 24u);
  for (const std::vector<uint8_t>& length : {std::vector<uint8_t>{0x80, 0, 0, 0}, std::vector<uint8_t>{0, 0, 0, 0},
                                             std::vector<uint8_t>{0x7f, 0xff, 0xff, 0xff}}) {
    std::vector<uint8_t> bad = bytes;
    std::copy(length.begin(), length.end(), bad.begin() + 20);
    Event ev;
    std::string error;
    EXPECT_FALSE(lcm_adapter::Decode("SLAM_STATUS", bad.data(), bad.size(), ChannelRoles{}, &ev, &error));
    EXPECT_NE(error.find("map_path length"), std::string::npos) << error;
  }
}

// Found by the 60 s fuzz run: the same overflow in the Winter 2023 grid's slam_map_location, whose
// length sits at byte 44 (after the fingerprint, utime, origin, resolution, size, count and mode).
TEST(LcmMessages, Winter2023GridStringLengthIsChecked) {
  mbot_w23::occupancy_grid_t g{};
  g.utime = 1;
  g.meters_per_cell = 0.05f;
  g.width = g.height = 1;
  g.num_cells = 1;
  g.cells = {0};
  g.slam_map_location = "map";
  std::vector<uint8_t> bytes(g.getEncodedSize());
  g.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  Event ev;
  std::string error;
  ASSERT_TRUE(lcm_adapter::Decode("SLAM_MAP", bytes.data(), bytes.size(), ChannelRoles{}, &ev, &error)) << error;
  bytes[44] = 0x80, bytes[45] = bytes[46] = bytes[47] = 0;
  EXPECT_FALSE(lcm_adapter::Decode("SLAM_MAP", bytes.data(), bytes.size(), ChannelRoles{}, &ev, &error));
  EXPECT_NE(error.find("slam_map_location length"), std::string::npos) << error;
}

TEST(LcmMessages, OdometryPoseRoundTrips) {
  const Event out = RoundTrip(Event{0, 7, "MBOT_ODOMETRY", EventKind::kOdometry, msgs::Pose2D{1.5, -2.0, 0.75}});
  ASSERT_EQ(out.kind, EventKind::kOdometry);
  const auto& p = std::get<msgs::Pose2D>(out.payload);
  EXPECT_FLOAT_EQ(p.x, 1.5f);
  EXPECT_FLOAT_EQ(p.y, -2.0f);
  EXPECT_FLOAT_EQ(p.theta, 0.75f);
}

Event DecodeBytes(const std::string& channel, const std::vector<uint8_t>& bytes) {
  const ChannelRoles roles;
  Event out;
  out.channel = channel;
  std::string error;
  const bool ok = lcm_adapter::Decode(channel, bytes.data(), bytes.size(), roles, &out, &error);
  EXPECT_TRUE(ok) << error;
  return out;
}

// The older generations (decoded only: the stack publishes the current types) — each message as
// its own generation's code writes it comes in as the typed event.
template <typename Msg>
Event DecodeOld(const std::string& channel, const Msg& m) {
  std::vector<uint8_t> bytes(m.getEncodedSize());
  m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return DecodeBytes(channel, bytes);
}

TEST(LcmMessages, LegacyGenerationDecodes) {
  mbot_legacy::mbot_encoder_t enc{};
  enc.utime = 10, enc.leftticks = 100, enc.rightticks = -50, enc.left_delta = 3, enc.right_delta = -2;
  const Event e = DecodeOld("MBOT_ENCODERS", enc);
  ASSERT_EQ(e.kind, EventKind::kEncoders);
  EXPECT_EQ(std::get<EncoderTicks>(e.payload).left_ticks, 100);
  EXPECT_EQ(std::get<EncoderTicks>(e.payload).right_delta, -2);
  mbot_legacy::mbot_imu_t imu{};
  imu.utime = 11, imu.gyro[2] = 0.5f, imu.tb_angles[2] = 1.25f;
  const Event i = DecodeOld("MBOT_IMU", imu);
  ASSERT_EQ(i.kind, EventKind::kImu);
  EXPECT_FLOAT_EQ(std::get<Imu>(i.payload).gyro_rad_s[2], 0.5f);
  EXPECT_FLOAT_EQ(std::get<Imu>(i.payload).angles_rpy_rad[2], 1.25f);
  mbot_legacy::mbot_motor_command_t cmd{};
  cmd.utime = 12, cmd.trans_v = 0.2f, cmd.angular_v = -0.4f;
  const Event c = DecodeOld("MBOT_MOTOR_COMMAND", cmd);
  ASSERT_EQ(c.kind, EventKind::kMotorCommand);
  EXPECT_FLOAT_EQ(std::get<MotorCommand>(c.payload).velocity.w_rad_s, -0.4f);
  mbot_legacy::pose_xyt_t pose{};
  pose.utime = 13, pose.x = 1.5f, pose.y = 2.5f, pose.theta = 0.5f;
  const Event p = DecodeOld("TRUE_POSE", pose);
  ASSERT_EQ(p.kind, EventKind::kGroundTruth);
  EXPECT_FLOAT_EQ(std::get<msgs::Pose2D>(p.payload).y, 2.5f);
}

TEST(LcmMessages, Winter2023AndMaebotGenerationsDecode) {
  mbot_w23::mbot_wheel_ctrl_t w{};
  w.utime = 20, w.left_motor_pwm = 0.3f, w.right_motor_pwm = -0.1f;
  const Event c = DecodeOld("MBOT_WHEEL_CTRL", w);
  ASSERT_EQ(c.kind, EventKind::kMotorCommand);
  EXPECT_EQ(std::get<MotorCommand>(c.payload).kind, MotorCommand::Kind::kPwm);
  EXPECT_FLOAT_EQ(std::get<MotorCommand>(c.payload).right_duty, -0.1f);
  maebot::maebot_encoders_t enc{};
  enc.utime = 21, enc.left_ticks_total = 7, enc.right_ticks_total = 9;
  const Event e = DecodeOld("MAEBOT_ENCODERS", enc);
  ASSERT_EQ(e.kind, EventKind::kEncoders);
  EXPECT_EQ(std::get<EncoderTicks>(e.payload).right_ticks, 9);
  maebot::maebot_motor_command_t m{};
  m.utime = 22, m.left_motor_speed = 0.5f, m.right_motor_speed = 0.7f, m.left_motor_enabled = true,
  m.right_motor_enabled = false;
  const Event d = DecodeOld("MAEBOT_MOTOR_COMMAND", m);
  ASSERT_EQ(d.kind, EventKind::kMotorCommand);
  EXPECT_FLOAT_EQ(std::get<MotorCommand>(d.payload).left_duty, 0.5f);
  EXPECT_EQ(std::get<MotorCommand>(d.payload).right_duty, 0.0);  // disabled
}

}  // namespace
}  // namespace mbot::lcmio
