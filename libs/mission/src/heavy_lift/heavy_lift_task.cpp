// Heavy Lift, the task's frame: sightings into crate estimates, the phase switch, arrivals and
// stalls, the report (the phases: search.cpp, approach.cpp, lift.cpp, out.cpp).
#include "heavy_lift_task.hpp"

namespace mbot::mission {
namespace heavy_lift {

void HeavyLiftTask::TagsSeen(Mission& m, const Pose2D& pose, const std::vector<TagSeen>& tags) {
  for (const TagSeen& t : tags) {
    const double range = std::hypot(t.x_m, t.y_m);
    if (range > o_.max_tag_range_m || (carried_ >= 0 && t.id == carried_)) continue;
    const Pose2D tag = pose.Compose({t.x_m, t.y_m, t.facing_rad});  // theta: the face's outward normal
    const double half = 0.5 * o_.crate_side_m;
    crates_[t.id].Add(tag.x - half * std::cos(tag.theta), tag.y - half * std::sin(tag.theta),
                      motion::WrapAngle(tag.theta), range, m.now_us());
    ++sightings_;
  }
}

bool HeavyLiftTask::Step(Mission& m, const Pose2D& pose) {
  const std::optional<mapping::SlamState> slam = m.slam_state();
  if (slam != mapping::SlamState::kLocalized && slam != mapping::SlamState::kMapping) {
    m.SetState(MissionState::kLocalizing, "waiting for SLAM");
    m.Hold();
    return false;
  }
  const int64_t now = m.now_us();
  switch (phase_) {
    case Phase::kStart:
      Fork(m, 0.0);
      home_ = {0, 0, 0};
      phase_ = Phase::kSurvey;
      phase_us_ = now;
      turned_ = 0, last_theta_ = pose.theta;
      break;
    case Phase::kSurvey:
      turned_ += std::abs(motion::WrapAngle(pose.theta - last_theta_));
      last_theta_ = pose.theta;
      if (turned_ < 2 * M_PI) {
        m.SetState(MissionState::kExploring, "one turn on the spot: looking for the crates");
        m.Drive(0.0, o_.search_turn_rad_s);
        return false;
      }
      phase_ = Phase::kFind;  // a crate not seen in this turn is looked for elsewhere (Search)
      break;
    case Phase::kFind: return Find(m, pose);
    case Phase::kToStandOff: return true;  // the controller drives; Arrived moves on
    case Phase::kToViewpoint: return true;
    case Phase::kLook: return Look(m, pose);
    case Phase::kIn: return In(m, pose);
    case Phase::kLift: return Lift(m);
    case Phase::kSetDown: return SetDown(m);
    case Phase::kOut: return Out(m, pose);
    case Phase::kHome: return true;
    case Phase::kDone: break;
  }
  m.Hold();
  return false;
}

void HeavyLiftTask::Arrived(Mission& m, const std::string& how) {
  m.EndFinalLeg();
  if (phase_ == Phase::kToViewpoint) {  // there: a turn on the spot
    phase_ = Phase::kFind;
    turned_ = 0;
    turn_from_here_ = true;
    return;
  }
  if (phase_ == Phase::kHome) {
    phase_ = Phase::kDone;
    m.SetState(MissionState::kCompleted, std::to_string(stacked_) + " of " + std::to_string(o_.stack.size()) +
                                             " crates set down on their crates by the forklift's report; home (" + how +
                                             ")");
    return;
  }
  phase_ = Phase::kLook;
  phase_us_ = m.now_us();
}

void HeavyLiftTask::Stalled(Mission& m) {
  if (phase_ == Phase::kToViewpoint) --viewpoint_;  // that viewpoint again, from where the back-off ends
  if (phase_ == Phase::kToStandOff || phase_ == Phase::kToViewpoint) {
    phase_ = Phase::kFind;  // plan again from where the back-off ends
    phase_us_ = m.now_us();
  }
}

void HeavyLiftTask::AddToReport(MissionReport* r) const {
  r->crates = static_cast<int>(o_.stack.size());
  r->crates_lifted = lifted_;
  r->crates_set_down = stacked_;
  r->tag_sightings = sightings_;
}

void HeavyLiftTask::Fork(Mission& m, double height_m) {
  if (height_m == fork_cmd_) return;
  fork_cmd_ = height_m;
  m.CommandFork(height_m);
}

void HeavyLiftTask::Fail(Mission& m, const std::string& why) {
  phase_ = Phase::kDone;
  m.SetState(MissionState::kFailed, why);
  m.Hold();
}

bool HeavyLiftTask::PlannerReady(Mission& m) {
  if (!m.map()) return false;
  if (!planner_.has_map() || planned_map_ != m.map()) {
    planner_.SetMap(planning::ObstacleDistanceGrid(*m.map(), distance_));
    planned_map_ = m.map();
  }
  return true;
}

}  // namespace heavy_lift

std::unique_ptr<Task> MakeHeavyLiftTask(const MissionOptions& options) {
  return std::make_unique<heavy_lift::HeavyLiftTask>(options);
}

}  // namespace mbot::mission
