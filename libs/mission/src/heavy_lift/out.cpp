// Heavy Lift, back off and home: along the line the robot came in on, then the next step, or home.
#include <algorithm>
#include <cmath>

#include "heavy_lift_task.hpp"
#include "mbot/common/strings.hpp"

namespace mbot::mission::heavy_lift {

void HeavyLiftTask::StartOut(Mission& m, const std::string& what) {
  line_ = {};
  phase_ = Phase::kOut;
  phase_us_ = m.now_us();
  progress_ = {m.now_us(), -1e9};
  m.SetState(MissionState::kDriving, what + ": backing off");
  out_started_ = false;
}

bool HeavyLiftTask::Out(Mission& m, const Pose2D& pose) {
  if (!out_started_) {
    line_ = pose;
    out_started_ = true;
  }
  if (!FollowLine(m, pose, -o_.retreat_m, false)) return false;
  m.Hold();
  if (picking()) Fork(m, 0.0);  // after a stack, or a miss: tines down for the next crate
  if (just_set_down_) {
    just_set_down_ = false;
    ++job_;  // this step is done
    attempts_ = 0;
  }
  if (job_ == o_.stack.size()) {
    if (!PlannerReady(m)) return false;
    const planning::PlanResult r = planner_.PlanSteppingOut(pose, home_);
    if (r.status != planning::PlanStatus::kFound) {
      Fail(m, "no path home: " + std::string(planning::ToString(r.status)));
      return false;
    }
    m.SetGoal(home_);
    m.SetPath(r.path);
    m.SetState(MissionState::kReturningHome, std::to_string(stacked_) + " crates stacked; home");
    phase_ = Phase::kHome;
    return false;
  }
  phase_ = Phase::kFind;
  phase_us_ = m.now_us();
  turned_ = 0, last_theta_ = pose.theta;
  return false;
}

}  // namespace mbot::mission::heavy_lift
