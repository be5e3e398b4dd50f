#include "mbot/mission/mission.hpp"

#include <algorithm>
#include <cmath>

#include "mbot/common/log.hpp"
#include "mbot/common/strings.hpp"
#include "tasks.hpp"

namespace mbot::mission {
namespace {

using motion::Pose2D;
using motion::TimedPose;

// Within this many final tolerances of the goal, a correction only turns on the spot, and after a
// first correction the position counts as reached.
constexpr double kTurnOnlyWithin = 1.5;

// Paths ending this close to the previous one's end lead to the same goal (the stall budget carries on).
constexpr double kSameGoalM = 0.10;

}  // namespace

const char* ToString(TaskKind kind) {
  switch (kind) {
    case TaskKind::kWaypoints: return "waypoints";
    case TaskKind::kExplore: return "explore";
    case TaskKind::kWarehouse: return "warehouse";
    case TaskKind::kFollow: return "follow";
    case TaskKind::kHeavyLift: return "heavy_lift";
  }
  return "?";
}

Mission::Mission(const MissionOptions& options, uint64_t seed)
    : o_(options), task_(MakeTask(o_, seed)), controller_(o_.controller), seed_(seed) {
  if (o_.explore_first && o_.task != TaskKind::kExplore) {
    MissionOptions explore = o_;
    explore.task = TaskKind::kExplore;
    task_ = MakeTask(explore, seed);
    exploring_first_ = true;
  }
}

Mission::~Mission() = default;

void Mission::OnPoseEstimate(int64_t t_us, const Pose2D& pose) {
  slam_ = {t_us, pose};
  has_slam_ = true;
  if (first_slam_us_ < 0) first_slam_us_ = t_us;
}

void Mission::OnMap(std::shared_ptr<const mapping::OccupancyGrid> map) {
  raw_map_ = std::move(map);
  MarkBumps();
}

// The map the tasks plan on: SLAM's, with a disc of kBumpRadiusM occupied at each recent bump.
void Mission::MarkBumps() {
  constexpr double kBumpRadiusM = 0.03;
  const int64_t keep_us = static_cast<int64_t>(o_.bump_keep_s * 1e6);
  bumps_.erase(std::remove_if(bumps_.begin(), bumps_.end(),
                              [&](const motion::TimedPose& b) { return t_us_ - b.t_us > keep_us; }),
               bumps_.end());
  if (!raw_map_ || bumps_.empty()) {
    map_ = raw_map_;
    return;
  }
  auto marked = std::make_shared<mapping::OccupancyGrid>(*raw_map_);
  const double res = marked->resolution();
  const int reach = static_cast<int>(std::ceil(kBumpRadiusM / res));
  for (const motion::TimedPose& b : bumps_) {
    int cx = 0, cy = 0;
    marked->WorldToCell(b.pose.x, b.pose.y, &cx, &cy);
    for (int dy = -reach; dy <= reach; ++dy) {
      for (int dx = -reach; dx <= reach; ++dx) {
        if (std::hypot(dx, dy) * res > kBumpRadiusM + 0.5 * res || !marked->IsInside(cx + dx, cy + dy)) continue;
        marked->at(cx + dx, cy + dy) = 127;
      }
    }
  }
  map_ = std::move(marked);
}

void Mission::OnSlamState(mapping::SlamState state) { slam_state_ = state; }

void Mission::OnPath(const std::vector<Pose2D>& path) { task_->PathReceived(path); }

void Mission::OnTags(int64_t t_us, const std::vector<TagSeen>& tags) {
  Pose2D pose;
  if (PoseAt(t_us, &pose)) task_->TagsSeen(*this, pose, tags);
}

bool Mission::PoseAt(int64_t t_us, Pose2D* pose) const {
  Pose2D odo_then;
  return motion::InterpolateAt(odometry_, t_us, 200'000, &odo_then) && FromOdometry(odo_then, pose);
}

void Mission::CommandFork(double height_m) {
  if (out_) out_->emplace_back(std::in_place_type<ForkOut>, ForkOut{height_m});
}

MissionReport Mission::Report() const {
  MissionReport r;
  r.task = o_.task;
  r.status = status_;
  r.commands = commands_, r.paths = paths_, r.stale_pose_stops = stale_stops_;
  r.corrections = total_corrections_, r.stall_recoveries = recoveries_, r.bumps = bumps_marked_;
  r.odometry_restarts = continuity_.restarts();
  r.odometry_outliers = continuity_.outliers(), r.odometry_duplicates = continuity_.duplicates();
  r.last_command = last_sent_;
  r.rounds = rounds_ + 1;
  task_->AddToReport(&r);
  return r;
}

std::vector<MissionOutput> Mission::OnOdometry(int64_t t_us, const Pose2D& raw_odometry, int64_t stamp_us) {
  std::vector<MissionOutput> out;
  out_ = &out;
  t_us_ = t_us;
  if (!odometry_.empty() && t_us < odometry_.back().t_us) return out;  // late: the series stays in order
  odometry_.push_back({t_us, continuity_.Update(t_us, raw_odometry, stamp_us)});
  if (odometry_.front().t_us < t_us - 10'000'000) {  // trim to 5 s now and then, not every message
    odometry_.erase(odometry_.begin(), std::lower_bound(odometry_.begin(), odometry_.end(), t_us - 5'000'000,
                                                        [](const TimedPose& p, int64_t t) { return p.t_us < t; }));
  }
  const double dt = last_control_us_ >= 0 ? (t_us - last_control_us_) * 1e-6 : 0.0;
  last_control_us_ = t_us;
  Pose2D pose;
  if (!PoseNow(&pose) || (t_us - first_slam_us_) * 1e-6 < o_.start_delay_s) {
    SetState(MissionState::kInitializing, "waiting for SLAM");
    Hold();
  } else if ((t_us - slam_.t_us) * 1e-6 > o_.max_pose_age_s) {
    ++stale_stops_;
    SetState(status_.state, "SLAM pose stale: stopped");
    Hold();
  } else if (manual_) {
    ManualStep(pose, dt);
  } else if ((status_.state == MissionState::kCompleted || status_.state == MissionState::kIncomplete) &&
             exploring_first_) {
    exploring_first_ = false;  // explored and home: now the task, on the map just made
    task_ = MakeTask(o_, seed_);
    final_leg_ = false;
    SetState(MissionState::kInitializing, std::string("explored; now the ") + ToString(o_.task));
    Hold();
  } else if (status_.state == MissionState::kCompleted && rounds_ < o_.repeat) {
    ++rounds_;  // a soak: the task again, with the next seed (a warehouse's next order)
    task_ = MakeTask(o_, seed_ + static_cast<uint64_t>(rounds_));
    final_leg_ = false;
    SetState(MissionState::kInitializing,
             "round " + std::to_string(rounds_ + 1) + " of " + std::to_string(o_.repeat + 1));
    Hold();
  } else if (IsFinal(status_.state) && !task_->Resumes()) {
    Hold();  // done (follow: until the next path, which a failure does not end)
  } else if (task_->Step(*this, pose) && !Recovering()) {
    const motion::VelocityCommand c = controller_.Update(Predict(pose), dt);
    Send(c.v_m_s, c.w_rad_s);
    last_command_ = c;
    std::string how;
    if (final_leg_ && controller_.arrived() && Settled(pose, &how)) task_->Arrived(*this, how);
  }
  out_ = nullptr;
  return out;
}

// The pose now: the SLAM pose at its scan, moved on by what odometry says happened since.
bool Mission::PoseNow(Pose2D* pose) const { return !odometry_.empty() && FromOdometry(odometry_.back().pose, pose); }

// The SLAM pose moved on by odometry from the SLAM pose's time to where odometry says `odometry`.
bool Mission::FromOdometry(const Pose2D& odometry, Pose2D* pose) const {
  if (!has_slam_ || odometry_.empty()) return false;
  Pose2D odo_slam;
  if (!motion::InterpolateAt(odometry_, slam_.t_us, 200'000, &odo_slam)) return false;
  *pose = slam_.pose.Compose(odo_slam.Inverse().Compose(odometry));
  return true;
}

// A robot pushing against a wall stalls: its wheels (hence odometry) stop while it is told to
// drive. After `stuck_s` of that, back off for `backoff_s`, then let the controller (and the task,
// which replans from the new pose) take over again.
bool Mission::Recovering() {
  if (t_us_ < backoff_until_us_) {
    Send(-0.1, 0.0);
    return true;
  }
  const motion::VelocityCommand v = MeasuredVelocity();
  const bool pushing = std::abs(last_command_.v_m_s) > 0.05 || std::abs(last_command_.w_rad_s) > 0.3;
  const bool still = std::abs(v.v_m_s) < 0.01 && std::abs(v.w_rad_s) < 0.05;
  if (!pushing || !still) {
    stuck_since_us_ = -1;
    return false;
  }
  if (stuck_since_us_ < 0) stuck_since_us_ = t_us_;
  if ((t_us_ - stuck_since_us_) * 1e-6 < o_.stuck_s) return false;
  if (++stalls_this_goal_ > o_.max_stalls) {
    SetState(MissionState::kFailed, "stalled " + std::to_string(stalls_this_goal_) + " times on the way to one goal");
    Hold();
    return true;
  }
  ++recoveries_;
  std::string marked;
  Pose2D at;
  if (o_.bump_ahead_m > 0 && std::abs(last_command_.v_m_s) > 0.05 && PoseNow(&at)) {
    const Pose2D bump = at.Compose({std::copysign(o_.bump_ahead_m, last_command_.v_m_s), 0, 0});
    bumps_.push_back({t_us_, bump});
    if (bumps_.size() > 32) bumps_.erase(bumps_.begin());
    ++bumps_marked_;
    MarkBumps();
    marked = "; an obstacle marked at (" + Significant(bump.x, 3) + ", " + Significant(bump.y, 3) + ")";
  }
  mbot::log::Warn("mission: stalled for " + Significant(o_.stuck_s, 3) + " s while commanded to move: backing off" +
                  marked);
  stuck_since_us_ = -1;
  last_command_ = {};
  backoff_until_us_ = t_us_ + static_cast<int64_t>(o_.backoff_s * 1e6);
  task_->Stalled(*this);
  Send(-0.1, 0.0);
  return true;
}

// At the final pose (goal_): the controller has stopped commanding, but the wheels lag, so wait
// until the robot stands still, then check the pose; outside the tolerances, drive to it again.
// True once it stands at the goal (or the corrections are spent); *how says how well.
bool Mission::Settled(const Pose2D& pose, std::string* how) {
  const motion::VelocityCommand v = MeasuredVelocity();
  if (std::abs(v.v_m_s) > 0.005 || std::abs(v.w_rad_s) > 0.02) return false;
  const double d = std::hypot(goal_.x - pose.x, goal_.y - pose.y);
  const double e = std::abs(motion::WrapAngle(goal_.theta - pose.theta));
  // A diff-drive robot cannot step sideways: re-driving to a point a centimetre or two off turns
  // towards it (up to 90 degrees), creeps, and turns back, and can end worse than it began. So
  // the position tolerance is final_tolerance_m on arrival, and kTurnOnlyWithin times that once a
  // correction has been made; within it a wrong heading is corrected by turning on the spot.
  const double tolerance = o_.controller.final_tolerance_m * (corrections_ > 0 ? kTurnOnlyWithin : 1.0);
  const bool heading_ok = e <= o_.controller.final_heading_tolerance_rad;
  if ((d <= tolerance && heading_ok) || corrections_ >= o_.max_corrections) {
    *how = std::to_string(corrections_) + " corrections; off by " + Significant(d, 3) + " m, " +
           Significant(e * 180 / M_PI, 3) + " deg by its own estimate";
    return true;
  }
  ++corrections_, ++total_corrections_;
  const bool publish = task_->PublishesPaths();
  if (!heading_ok && d <= kTurnOnlyWithin * o_.controller.final_tolerance_m) {
    SetPath({Pose2D{pose.x, pose.y, goal_.theta}}, publish);
  } else {
    SetPath({goal_}, publish);
  }
  return false;
}

// Body velocity from odometry over the last 0.1 s.
motion::VelocityCommand Mission::MeasuredVelocity() const {
  if (odometry_.size() < 2) return {};
  const TimedPose& now = odometry_.back();
  size_t i = odometry_.size() - 1;
  while (i > 0 && now.t_us - odometry_[i].t_us < 100'000) --i;
  const double dt = (now.t_us - odometry_[i].t_us) * 1e-6;
  if (dt <= 0) return {};
  const Pose2D d = odometry_[i].pose.Inverse().Compose(now.pose);
  return {d.x / dt, d.theta / dt};
}

// The pose `control_lag_s` ahead at the velocity odometry measured over the last 0.1 s.
Pose2D Mission::Predict(const Pose2D& pose) const {
  if (o_.control_lag_s <= 0) return pose;
  return motion::StepUnicycle(pose, MeasuredVelocity(), o_.control_lag_s);
}

void Mission::SetState(MissionState state, const std::string& detail) {
  if (state == status_.state && detail == status_.detail) return;
  status_ = {state, detail};
  mbot::log::Info(std::string("mission: ") + ToString(state) + (detail.empty() ? "" : " (" + detail + ")"));
  if (out_) out_->emplace_back(std::in_place_type<MissionStatus>, status_);
}

void Mission::SetPath(const std::vector<Pose2D>& path, bool publish) {
  // A new goal (not a replan or a correction towards the same one) gets a fresh stall budget.
  if (!path.empty() && std::hypot(path.back().x - stall_goal_.x, path.back().y - stall_goal_.y) > kSameGoalM) {
    stall_goal_ = path.back();
    stalls_this_goal_ = 0;
  }
  controller_.SetPath(path);
  ++paths_;
  if (out_ && publish) out_->emplace_back(std::in_place_type<PathOut>, PathOut{path});
}

void Mission::SetGoal(const Pose2D& goal) {
  goal_ = goal;
  final_leg_ = true;
  corrections_ = 0;
}

void Mission::Hold() { Send(0, 0); }

void Mission::ShowExploration(ExplorationOut seen) {
  if (out_) out_->emplace_back(std::in_place_type<ExplorationOut>, std::move(seen));
}

void Mission::OnGoal(const Pose2D& goal) {
  manual_ = true;
  person_goal_ = goal;
  teleop_until_us_ = -1;
}

void Mission::OnTeleop(int64_t t_us, double v_m_s, double w_rad_s) {
  manual_ = true;
  person_goal_.reset();
  final_leg_ = false;
  const double v_max = o_.controller.max_speed_m_s, w_max = o_.controller.max_turn_rate_rad_s;
  teleop_ = {std::clamp(v_m_s, -v_max, v_max), std::clamp(w_rad_s, -w_max, w_max)};
  teleop_until_us_ = t_us + static_cast<int64_t>(o_.teleop_timeout_s * 1e6);
}

// A person's goal or teleop, instead of the task.
bool Mission::ManualStep(const Pose2D& pose, double dt) {
  if (teleop_until_us_ >= 0) {
    if (t_us_ <= teleop_until_us_) {
      SetState(MissionState::kDriving,
               "teleop: v " + Significant(teleop_.v_m_s, 3) + " m/s, w " + Significant(teleop_.w_rad_s, 3) + " rad/s");
      Send(teleop_.v_m_s, teleop_.w_rad_s);
      return true;
    }
    teleop_until_us_ = -1;  // the commands stopped coming: stop
    SetState(MissionState::kWaiting, "teleop ended: holding for a goal or teleop");
  }
  if (person_goal_) {
    if (!map_) {
      SetState(MissionState::kWaiting, "a goal was set, but there is no map to plan on yet");
      Hold();
      return false;
    }
    planning::AStarPlanner planner(o_.exploration.astar);
    planner.SetMap(planning::ObstacleDistanceGrid(*map_, o_.exploration.distance));
    const planning::PlanResult r = planner.PlanSteppingOut(pose, *person_goal_);
    const Pose2D goal = *person_goal_;
    person_goal_.reset();
    const std::string where = "(" + Significant(goal.x, 3) + ", " + Significant(goal.y, 3) + ")";
    if (r.status != planning::PlanStatus::kFound) {
      SetState(MissionState::kWaiting, "no path to the goal " + where + ": " + planning::ToString(r.status));
      Hold();
      return false;
    }
    SetGoal({goal.x, goal.y, r.path.back().theta});
    SetPath(r.path);
    SetState(MissionState::kDriving, "to the goal a person set " + where);
  }
  if (!final_leg_ || Recovering()) {
    if (!final_leg_) Hold();
    return false;
  }
  const motion::VelocityCommand c = controller_.Update(Predict(pose), dt);
  Send(c.v_m_s, c.w_rad_s);
  last_command_ = c;
  std::string how;
  if (controller_.arrived() && Settled(pose, &how)) {
    EndFinalLeg();
    SetState(MissionState::kArrived, "at the goal a person set (" + how + ")");
  }
  return true;
}

void Mission::Send(double v, double w) {
  ++commands_;
  last_sent_ = {v, w};
  if (out_) out_->emplace_back(std::in_place_type<motion::VelocityCommand>, motion::VelocityCommand{v, w});
}

}  // namespace mbot::mission
