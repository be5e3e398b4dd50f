#include <cctype>

#include "mbot/msgs/events.hpp"
#include "mbot/msgs/visitor.hpp"

namespace mbot::msgs {

const char* ToString(EventKind kind) {
  switch (kind) {
    case EventKind::kLidar: return "lidar";
    case EventKind::kOdometry: return "odometry";
    case EventKind::kEncoders: return "encoders";
    case EventKind::kImu: return "imu";
    case EventKind::kMotorCommand: return "motor command";
    case EventKind::kGroundTruth: return "ground truth";
    case EventKind::kReferencePose: return "reference pose";
    case EventKind::kMap: return "map";
    case EventKind::kPlanRequest: return "plan request";
    case EventKind::kWheelSpeed: return "wheel speed";
    case EventKind::kMotorSample: return "motor sample";
    case EventKind::kCollision: return "collision";
    case EventKind::kPoseEstimate: return "pose estimate";
    case EventKind::kPath: return "path";
    case EventKind::kSlamStatus: return "SLAM status";
    case EventKind::kMissionStatus: return "mission status";
    case EventKind::kParticles: return "particles";
    case EventKind::kTagSightings: return "tag sightings";
    case EventKind::kCameraFrame: return "camera frame";
    case EventKind::kForkliftCommand: return "forklift command";
    case EventKind::kForkliftStatus: return "forklift status";
    case EventKind::kCrates: return "crates";
    case EventKind::kGoal: return "goal";
    case EventKind::kTeleop: return "teleop";
    case EventKind::kFrontiers: return "frontiers";
    case EventKind::kObstacleDistance: return "obstacle distance";
    case EventKind::kScore: return "score";
    case EventKind::kSlamControl: return "SLAM control";
    case EventKind::kOther: return "other";
  }
  return "?";
}

std::string KeyName(EventKind kind) {
  std::string key = ToString(kind);
  for (char& c : key) c = c == ' ' ? '_' : static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return key;
}

std::optional<EventKind> KindFromKey(const std::string& key) {
  for (int i = 0; i < kEventKindCount; ++i) {
    if (KeyName(static_cast<EventKind>(i)) == key) return static_cast<EventKind>(i);
  }
  return std::nullopt;
}

namespace {
template <typename T, typename F>
bool With(const Event& e, F f) {
  const T* p = std::get_if<T>(&e.payload);
  return p && f(*p);
}
}  // namespace

bool Visit(const Event& e, EventVisitor& v) {
  switch (e.kind) {
    case EventKind::kLidar: return With<LidarScan>(e, [&](const auto& p) { return v.Lidar(e, p); });
    case EventKind::kOdometry:
    case EventKind::kGroundTruth:
    case EventKind::kReferencePose:
    case EventKind::kCollision:
    case EventKind::kGoal:
    case EventKind::kPoseEstimate: return With<Pose2D>(e, [&](const auto& p) { return v.Pose(e, p); });
    case EventKind::kEncoders: return With<EncoderTicks>(e, [&](const auto& p) { return v.Encoders(e, p); });
    case EventKind::kImu: return With<Imu>(e, [&](const auto& p) { return v.ImuReading(e, p); });
    case EventKind::kTeleop:
    case EventKind::kMotorCommand: return With<MotorCommand>(e, [&](const auto& p) { return v.Motors(e, p); });
    case EventKind::kWheelSpeed: return With<WheelSpeeds>(e, [&](const auto& p) { return v.Wheels(e, p); });
    case EventKind::kMap:
      return With<std::shared_ptr<const OccupancyGrid>>(e, [&](const auto& p) { return p && v.Map(e, *p); });
    case EventKind::kPlanRequest: return With<PlanRequest>(e, [&](const auto& p) { return v.Plan(e, p); });
    case EventKind::kMotorSample: return With<WheelSample>(e, [&](const auto& p) { return v.Sample(e, p); });
    case EventKind::kPath: return With<Path>(e, [&](const auto& p) { return v.PathPoses(e, p); });
    case EventKind::kSlamStatus: return With<SlamStatus>(e, [&](const auto& p) { return v.Slam(e, p); });
    case EventKind::kMissionStatus: return With<MissionStatus>(e, [&](const auto& p) { return v.Mission(e, p); });
    case EventKind::kParticles: return With<Particles>(e, [&](const auto& p) { return v.ParticleSet(e, p); });
    case EventKind::kTagSightings: return With<TagSightings>(e, [&](const auto& p) { return v.Tags(e, p); });
    case EventKind::kCameraFrame: return With<CameraFrame>(e, [&](const auto& p) { return v.Frame(e, p); });
    case EventKind::kForkliftCommand: return With<ForkliftCommand>(e, [&](const auto& p) { return v.Forklift(e, p); });
    case EventKind::kForkliftStatus:
      return With<ForkliftStatus>(e, [&](const auto& p) { return v.ForkliftState(e, p); });
    case EventKind::kCrates: return With<CrateStates>(e, [&](const auto& p) { return v.Crates(e, p); });
    case EventKind::kFrontiers: return With<Frontiers>(e, [&](const auto& p) { return v.FrontierSet(e, p); });
    case EventKind::kObstacleDistance:
      return With<std::shared_ptr<const DistanceGrid>>(e, [&](const auto& p) { return p && v.Distances(e, *p); });
    case EventKind::kScore: return With<ScoreStatus>(e, [&](const auto& p) { return v.Score(e, p); });
    case EventKind::kSlamControl: return With<SlamControl>(e, [&](const auto& p) { return v.SlamCommand(e, p); });
    case EventKind::kOther: return false;
  }
  return false;
}

}  // namespace mbot::msgs
