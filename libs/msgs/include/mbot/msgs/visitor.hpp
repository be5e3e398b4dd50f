// One method per kind of event: what a serializer (a transport's encoder, a viewer's, a report)
// implements. Visit() is the one place that maps a kind to its payload type, so a new kind of event
// is its type in events.hpp, its line here and in Visit, and a method in the serializers that
// carry it; nothing else changes.
#pragma once

#include "mbot/msgs/events.hpp"

namespace mbot::msgs {

class EventVisitor {
 public:
  virtual ~EventVisitor() = default;
  // Each returns true when it handled the event; the defaults handle nothing.
  virtual bool Lidar(const Event&, const LidarScan&) { return false; }
  // kOdometry, kGroundTruth, kReferencePose, kPoseEstimate, kCollision, kGoal: the kind says which.
  virtual bool Pose(const Event&, const Pose2D&) { return false; }
  virtual bool Encoders(const Event&, const EncoderTicks&) { return false; }
  virtual bool ImuReading(const Event&, const Imu&) { return false; }
  // kMotorCommand, kTeleop.
  virtual bool Motors(const Event&, const MotorCommand&) { return false; }
  virtual bool Wheels(const Event&, const WheelSpeeds&) { return false; }
  virtual bool Map(const Event&, const OccupancyGrid&) { return false; }
  virtual bool Plan(const Event&, const PlanRequest&) { return false; }
  virtual bool Sample(const Event&, const WheelSample&) { return false; }
  virtual bool PathPoses(const Event&, const Path&) { return false; }
  virtual bool Slam(const Event&, const SlamStatus&) { return false; }
  virtual bool Mission(const Event&, const MissionStatus&) { return false; }
  virtual bool ParticleSet(const Event&, const Particles&) { return false; }
  virtual bool Tags(const Event&, const TagSightings&) { return false; }
  virtual bool Frame(const Event&, const CameraFrame&) { return false; }
  virtual bool Forklift(const Event&, const ForkliftCommand&) { return false; }
  virtual bool ForkliftState(const Event&, const ForkliftStatus&) { return false; }
  virtual bool Crates(const Event&, const CrateStates&) { return false; }
  virtual bool FrontierSet(const Event&, const Frontiers&) { return false; }
  virtual bool Distances(const Event&, const DistanceGrid&) { return false; }
  virtual bool Score(const Event&, const ScoreStatus&) { return false; }
  virtual bool SlamCommand(const Event&, const SlamControl&) { return false; }
};

// Calls the visitor's method for the event's kind with its payload. False when the visitor did not
// handle it, the kind is kOther, or the payload does not hold the kind's type.
bool Visit(const Event& event, EventVisitor& visitor);

}  // namespace mbot::msgs
