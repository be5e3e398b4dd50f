// The pipeline's topic names: the channel an event travels on inside a run. They are the botlab's
// LCM channel names, so a log replays with no table at all; a transport maps them to its own names
// (a TopicTable per transport: LCM keeps these, ROS 2 has /scan, /odom, /cmd_vel) at its edge.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace mbot::config {
class Section;
}

namespace mbot::msgs::topics {

// The robot's sensors and actuators.
inline constexpr const char* kLidar = "LIDAR";
inline constexpr const char* kOdometry = "MBOT_ODOMETRY";
inline constexpr const char* kEncoders = "MBOT_ENCODERS";
inline constexpr const char* kImu = "MBOT_IMU";
inline constexpr const char* kMotorPwm = "MBOT_MOTOR_PWM";
inline constexpr const char* kMotorVelocity = "MBOT_MOTOR_VEL";
inline constexpr const char* kVelocityCommand = "MBOT_VEL_CMD";
inline constexpr const char* kCamera = "CAMERA";
inline constexpr const char* kForkliftCommand = "MBOT_FORKLIFT_CMD";
inline constexpr const char* kForkliftStatus = "MBOT_FORKLIFT_STATUS";
inline constexpr const char* kTimesync = "MBOT_TIMESYNC";
inline constexpr const char* kSystemReset = "MBOT_SYSTEM_RESET";
// The autonomy's outputs.
inline constexpr const char* kSlamPose = "SLAM_POSE";
inline constexpr const char* kSlamMap = "SLAM_MAP";
inline constexpr const char* kSlamParticles = "SLAM_PARTICLES";
inline constexpr const char* kSlamStatus = "SLAM_STATUS";
inline constexpr const char* kPath = "CONTROLLER_PATH";
inline constexpr const char* kMissionStatus = "MISSION_STATUS";
inline constexpr const char* kExplorationStatus = "EXPLORATION_STATUS";
inline constexpr const char* kFrontiers = "EXPLORATION_FRONTIERS";
inline constexpr const char* kObstacleDistance = "OBSTACLE_DISTANCE";
inline constexpr const char* kScore = "REFEREE_SCORE";
inline constexpr const char* kTags = "MBOT_APRILTAG_ARRAY";
// Older generations' names a log may use (2017-2022 staff logs, the motion-capture rig).
inline constexpr const char* kLegacyOdometry = "ODOMETRY";
inline constexpr const char* kGroundTruthPose = "GROUND_TRUTH_POSE";
// The simulator's truth (for the referee and for pictures; the autonomy never reads them).
inline constexpr const char* kTruePose = "TRUE_POSE";
inline constexpr const char* kCollision = "SIM_COLLISION";
inline constexpr const char* kCrates = "SIM_CRATES";

}  // namespace mbot::msgs::topics

namespace mbot::msgs {

// A transport's names for the pipeline's topics: `defaults` (topic → wire name, every topic the
// transport carries by default), overridden from config. Topics not in the table keep their name.
class TopicTable {
 public:
  TopicTable() = default;
  explicit TopicTable(std::map<std::string, std::string> defaults);
  // Reads `key` of the section: "TOPIC:wire_name" pairs that override the defaults; a wire name
  // used twice is an error naming the key.
  void Parse(config::Section& section, const std::string& key);
  std::string Wire(const std::string& topic) const;
  // The topic a wire name carries (the reverse of Wire), or the name itself.
  std::string Topic(const std::string& wire) const;
  const std::map<std::string, std::string>& entries() const { return to_wire_; }

 private:
  std::map<std::string, std::string> to_wire_, to_topic_;
};

}  // namespace mbot::msgs
