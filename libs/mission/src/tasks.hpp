// The tasks behind the mission (one class each): each decides where to go; the Mission around it
// drives there, recovers from stalls and settles at the goal.
#pragma once

#include <memory>
#include <string>

#include "mbot/mission/mission.hpp"

namespace mbot::mission {

class Task {
 public:
  virtual ~Task() = default;
  // One control step before the controller runs, at the pose now: set paths, goals and states
  // through `m`. False when the task has commanded the robot itself this step (m.Hold()).
  virtual bool Step(Mission& m, const motion::Pose2D& pose) = 0;
  // The goal is reached and the robot stands at it; `how` says how well.
  virtual void Arrived(Mission& m, const std::string& how) = 0;
  // The robot stalled and backs off.
  virtual void Stalled(Mission& /*m*/) {}
  // heavy_lift: tags seen in a camera frame, with the robot's pose (map frame) when it was taken.
  virtual void TagsSeen(Mission& /*m*/, const motion::Pose2D& /*pose*/, const std::vector<TagSeen>& /*tags*/) {}
  // A path from outside arrived (follow).
  virtual void PathReceived(const std::vector<motion::Pose2D>& /*path*/) {}
  // After completing or failing, the task takes up work again (follow: a new path).
  virtual bool Resumes() const { return false; }
  // Corrections at the goal are published as paths (not for paths that came from outside).
  virtual bool PublishesPaths() const { return true; }
  virtual void AddToReport(MissionReport* /*r*/) const {}
};

std::unique_ptr<Task> MakeTask(const MissionOptions& options, uint64_t seed);
std::unique_ptr<Task> MakeHeavyLiftTask(const MissionOptions& options);  // heavy_lift_task.cpp

}  // namespace mbot::mission
