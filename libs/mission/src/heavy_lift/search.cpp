// Heavy Lift, search and planning: find the crate of the step (look for one not seen yet from round the
// crates seen) and plan to a stand-off before one of its faces.
#include <algorithm>
#include <cmath>

#include "heavy_lift_task.hpp"
#include "mbot/common/strings.hpp"

namespace mbot::mission::heavy_lift {

// A crate not seen yet: it may be hidden behind another or too far to read. Turn on the spot,
// then go round the crates seen (the day's crates to lift stand in one area): a viewpoint 0.8 m
// from their centre, first on the robot's side, then a quarter turn round either way, then the
// far side; a turn on the spot at each.
bool HeavyLiftTask::Search(Mission& m, const Pose2D& pose) {
  if (turn_from_here_) last_theta_ = pose.theta, turn_from_here_ = false;
  if (turned_ < 2 * M_PI) {
    turned_ += std::abs(motion::WrapAngle(pose.theta - last_theta_));
    last_theta_ = pose.theta;
    m.SetState(MissionState::kExploring, "looking for " + Name() + " (turning on the spot)");
    m.Drive(0.0, o_.search_turn_rad_s);
    return false;
  }
  double cx = 0, cy = 0;
  int n = 0;
  for (const auto& [first, second] : o_.stack) {  // the crates to lift that were seen, else any
    auto it = crates_.find(first);
    if (first == carried_ || it == crates_.end() || !it->second.known()) continue;
    const Pose2D c = it->second.Get();
    cx += c.x, cy += c.y, ++n;
  }
  const bool lift_crates_seen = n > 0;
  for (const auto& [id, e] : crates_) {
    if (lift_crates_seen || id == carried_ || !e.known()) continue;
    const Pose2D c = e.Get();
    cx += c.x, cy += c.y, ++n;
  }
  if (n == 0 || !PlannerReady(m)) {
    if (n == 0)
      Fail(m, Name() + ": no crate seen in a turn on the spot");
    else
      m.Hold();
    return false;
  }
  cx /= n, cy /= n;
  const double away = std::atan2(pose.y - cy, pose.x - cx);
  const double offsets[] = {0.0, kQuarter, -kQuarter, M_PI};
  while (viewpoint_ < 4) {
    const double a = away + offsets[viewpoint_++];
    const Pose2D goal{cx + 0.8 * std::cos(a), cy + 0.8 * std::sin(a), motion::WrapAngle(a + M_PI)};
    const planning::PlanResult r = planner_.PlanSteppingOut(pose, goal);
    if (r.status != planning::PlanStatus::kFound) continue;
    m.SetGoal(goal);
    m.SetPath(r.path);
    m.SetState(MissionState::kExploring, "looking for " + Name() + " from another side of the crates");
    phase_ = Phase::kToViewpoint;
    return true;
  }
  Fail(m, Name() + ": its tag was not seen from the start or from round the crates");
  return false;
}

bool HeavyLiftTask::Find(Mission& m, const Pose2D& pose) {
  auto it = crates_.find(target());
  if (it == crates_.end() || !it->second.known()) return Search(m, pose);
  viewpoint_ = 0;
  if ((no_path_since_us_ >= 0 && failed_map_ == m.map()) || !PlannerReady(m)) {
    m.Hold();  // no map yet, or the one no path was found in: wait for the next
    return false;
  }
  // The face towards the robot first, then the others by how far round the crate they are.
  const Pose2D c = it->second.Get();
  const double towards = FaceTowards(c, pose);
  planning::PlanResult r;
  Pose2D goal;
  for (const int k : {0, 1, -1, 2}) {
    normal_ = motion::WrapAngle(towards + k * kQuarter);
    goal = StandOff(c, normal_, picking() ? o_.standoff_m : o_.place_standoff_m);
    r = planner_.PlanSteppingOut(pose, goal);
    if (r.status == planning::PlanStatus::kFound) break;
  }
  if (r.status != planning::PlanStatus::kFound) {
    // The map may not show the way yet (young cells are not free enough): look again, for a while.
    if (no_path_since_us_ < 0) no_path_since_us_ = m.now_us();
    failed_map_ = m.map();
    if ((m.now_us() - no_path_since_us_) * 1e-6 > o_.no_path_wait_s) {
      Fail(m, "no path to a stand-off before any face of " + Name() + " for " + Significant(o_.no_path_wait_s, 3) +
                  " s: " + planning::ToString(r.status));
      return false;
    }
    m.SetState(MissionState::kExploring, "no path to " + Name() + " yet (" + planning::ToString(r.status) + ")");
    m.Hold();
    return false;
  }
  no_path_since_us_ = -1;
  m.SetGoal(goal);
  m.SetPath(r.path);
  m.SetState(MissionState::kDriving, "to " + Name());
  phase_ = Phase::kToStandOff;
  return true;
}

}  // namespace mbot::mission::heavy_lift
