// Round trips through the LCM edge (lcm_adapter::Encode → Decode, the current mbot_lcm_msgs types):
// what the stack publishes comes back as the same typed event.
#include "lcm_messages.hpp"

#include <gtest/gtest.h>

namespace mbot::drivers {
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
  using mission::MissionState;
  const std::pair<MissionState, MissionState> cases[] = {{MissionState::kInitializing, MissionState::kInitializing},
                                                         {MissionState::kExploring, MissionState::kExploring},
                                                         {MissionState::kReturningHome, MissionState::kReturningHome},
                                                         {MissionState::kCompleted, MissionState::kCompleted},
                                                         {MissionState::kFailed, MissionState::kFailed},
                                                         {MissionState::kDriving, MissionState::kExploring},
                                                         {MissionState::kLifting, MissionState::kExploring}};
  for (const auto& [sent, received] : cases) {
    const Event out =
        RoundTrip(Event{0, 9, "EXPLORATION_STATUS", EventKind::kMissionStatus, mission::MissionStatus{sent, "x"}});
    ASSERT_EQ(out.kind, EventKind::kMissionStatus);
    EXPECT_EQ(std::get<mission::MissionStatus>(out.payload).state, received) << mission::ToString(sent);
  }
}

TEST(LcmMessages, SlamStatusCarriesTheMode) {
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(lcm_adapter::Encode(
      Event{0, 1, "SLAM_STATUS", EventKind::kSlamStatus,
            mapping::SlamStatus{mapping::SlamState::kLocalized, mapping::SlamMode::kLocalization, 0.1}},
      &bytes));
  const lcm_adapter::TypeInfo* type = lcm_adapter::LookUp(lcm_adapter::Fingerprint(bytes.data(), bytes.size()));
  ASSERT_NE(type, nullptr);
  EXPECT_EQ(type->type, "slam_status_t");
}

TEST(LcmMessages, OdometryPoseRoundTrips) {
  const Event out = RoundTrip(Event{0, 7, "MBOT_ODOMETRY", EventKind::kOdometry, motion::Pose2D{1.5, -2.0, 0.75}});
  ASSERT_EQ(out.kind, EventKind::kOdometry);
  const auto& p = std::get<motion::Pose2D>(out.payload);
  EXPECT_FLOAT_EQ(p.x, 1.5f);
  EXPECT_FLOAT_EQ(p.y, -2.0f);
  EXPECT_FLOAT_EQ(p.theta, 0.75f);
}

}  // namespace
}  // namespace mbot::drivers
