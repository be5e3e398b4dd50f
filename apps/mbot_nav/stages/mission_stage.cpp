// `mission`: the robot's autonomy after SLAM — what to do (follow a circuit of waypoints, explore
// and return home, the Warehouse's deliveries in a known map once global localization has settled,
// or drive the paths a GUI sends), how to get there (A* paths) and the motion controller that turns
// the pose into velocity commands. It runs on every odometry message (the firmware's 50 Hz): the
// pose is the latest SLAM pose moved on by the odometry since that scan, the command goes out on
// MBOT_VEL_CMD (to the simulator, or to a robot over LCM). States go out as kStatus events.
// The same stage drives the simulator, a live robot, and does nothing harmful on a log (nobody
// listens to its commands there).
#include <algorithm>
#include <cmath>
#include <iostream>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/drivers/sim_world.hpp"
#include "mbot/motion/motion_controller.hpp"
#include "mbot/planning/exploration.hpp"
#include "mbot/planning/planning_config.hpp"
#include "warehouse.hpp"
#include "report.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

using drivers::EventKind;
using motion::Pose2D;
using motion::TimedPose;

enum class Task { kWaypoints, kExplore, kWarehouse, kFollow };

// Within this many final tolerances of the goal, a correction only turns on the spot, and after a
// first correction the position counts as reached.
constexpr double kTurnOnlyWithin = 1.5;

// Paths ending this close to the previous one's end lead to the same goal (the stall budget carries on).
constexpr double kSameGoalM = 0.10;


const char* TaskName(Task t) {
  return t == Task::kWaypoints ? "waypoints" : t == Task::kExplore ? "explore" : t == Task::kWarehouse ? "warehouse" : "follow";
}

struct MissionOptions {
  Task task = Task::kWaypoints;
  std::vector<Pose2D> waypoints;        // start frame; empty with waypoints_from_arena
  bool waypoints_from_arena = true;     // the source's arena file, `waypoint` poses relative to `start`
  motion::MotionControllerOptions controller;
  planning::ExplorationOptions exploration;
  double explore_period_s = 0.25;       // explorer updates at most this often [s]
  double start_delay_s = 0.5;           // stand still this long after the first SLAM pose (map the start)
  double max_pose_age_s = 1.0;          // stop when the SLAM pose is older than this [s]
  // The wheels answer a command late (the firmware filters v, ω and the PWM; the motors lag): the
  // controller is given the pose predicted this far ahead at the measured velocity.
  double control_lag_s = 0.2;
  int max_corrections = 5;
  double stuck_s = 1.0;                 // commanded to move but not moving this long: back off
  double backoff_s = 0.6;               // reversing at 0.1 m/s
  int max_stalls = 10;                  // stalls on the way to one goal before the mission gives up
  double dwell_s = warehouse::kDwellS + 0.5;  // warehouse: standing at a stop (lifting, setting down) [s]
  std::string status_channel = "MISSION_STATUS";
  std::string slam_status_channel = "SLAM_STATUS";
  std::string path_channel = "CONTROLLER_PATH";  // follow: paths sent by a GUI arrive here
};

class MissionStage : public Stage {
 public:
  explicit MissionStage(MissionOptions o)
      : o_(std::move(o)), controller_(o_.controller), explorer_(o_.exploration) {}

  void Start(const RunContext& ctx) override {
    bus_ = ctx.bus;
    if (o_.task == Task::kWarehouse) {
      stops_ = warehouse::Stops(drivers::World::Load(ctx.source_path), ctx.seed);
      planner_ = planning::AStarPlanner(o_.exploration.astar);
    }
    if (o_.task == Task::kWaypoints && o_.waypoints.empty()) {
      if (!o_.waypoints_from_arena) throw std::runtime_error("mission: no waypoints given");
      const drivers::World world = drivers::World::Load(ctx.source_path);
      const auto starts = world.PosesLabelled("start");
      const auto points = world.PosesLabelled("waypoint");
      if (starts.empty() || points.empty()) {
        throw std::runtime_error("mission: waypoints = arena, but " + ctx.source_path +
                                 " has no 'pose start' and 'pose waypoint' lines");
      }
      const Pose2D inv = starts[0].Inverse();
      for (const Pose2D& w : points) o_.waypoints.push_back(inv.Compose(w));
    }
  }

  void OnEvent(const drivers::Event& ev) override {
    switch (ev.kind) {
      case EventKind::kPoseEstimate:
        slam_ = {ev.t_us, std::get<Pose2D>(ev.payload)};
        has_slam_ = true;
        if (first_slam_us_ < 0) first_slam_us_ = ev.t_us;
        return;
      case EventKind::kMap:
        map_ = std::get<std::shared_ptr<const mapping::OccupancyGrid>>(ev.payload);
        return;
      case EventKind::kStatus:
        if (ev.channel == o_.slam_status_channel) slam_status_ = std::get<drivers::Status>(ev.payload);
        return;
      case EventKind::kPath:
        if (o_.task == Task::kFollow && ev.channel == o_.path_channel) gui_path_ = std::get<drivers::Path>(ev.payload).poses;
        return;
      case EventKind::kOdometry:
        odometry_.push_back({ev.t_us, std::get<Pose2D>(ev.payload)});
        if (odometry_.front().t_us < ev.t_us - 10'000'000) {  // trim to 5 s now and then, not every message
          odometry_.erase(odometry_.begin(), std::lower_bound(odometry_.begin(), odometry_.end(), ev.t_us - 5'000'000,
                                                              [](const TimedPose& p, int64_t t) { return p.t_us < t; }));
        }
        Control(ev.t_us);
        return;
      default:
        return;
    }
  }

  void Finish(const RunContext& ctx, bool interrupted) override {
    std::ostringstream j;
    j << "{\n  \"task\": " << JsonString(TaskName(o_.task))
      << ",\n  \"state\": " << JsonString(state_) << ",\n  \"detail\": " << JsonString(detail_)
      << ",\n  \"interrupted\": " << (interrupted ? "true" : "false") << ",\n  \"commands\": " << commands_
      << ",\n  \"paths\": " << paths_ << ",\n  \"stale_pose_stops\": " << stale_stops_
      << ",\n  \"corrections\": " << total_corrections_ << ",\n  \"stall_recoveries\": " << recoveries_;
    if (o_.task == Task::kWarehouse) {
      j << ",\n  \"stops\": " << stops_.size() << ",\n  \"stops_done\": " << stop_index_;
    }
    j << "\n}\n";
    WriteFileAtomically(ctx.output_dir + "/mission.json", [&](std::ostream& out) { out << j.str(); });
  }

 private:
  // The pose now: the SLAM pose at its scan, moved on by what odometry says happened since.
  bool PoseNow(Pose2D* pose) const {
    if (!has_slam_ || odometry_.empty()) return false;
    Pose2D odo_then;
    if (!motion::InterpolateAt(odometry_, slam_.t_us, 200'000, &odo_then)) return false;
    const Pose2D delta = odo_then.Inverse().Compose(odometry_.back().pose);
    *pose = slam_.pose.Compose(delta);
    return true;
  }

  // A robot pushing against a wall stalls: its wheels (hence odometry) stop while it is told to
  // drive. After `stuck_s` of that, back off for `backoff_s`, then let the controller (and the
  // explorer, which replans from the new pose) take over again.
  bool Recovering(int64_t t_us) {
    if (t_us < backoff_until_us_) {
      Send(-0.1, 0.0, t_us);
      return true;
    }
    const motion::VelocityCommand v = MeasuredVelocity();
    const bool pushing = std::abs(last_command_.v_m_s) > 0.05 || std::abs(last_command_.w_rad_s) > 0.3;
    const bool still = std::abs(v.v_m_s) < 0.01 && std::abs(v.w_rad_s) < 0.05;
    if (!pushing || !still) {
      stuck_since_us_ = -1;
      return false;
    }
    if (stuck_since_us_ < 0) stuck_since_us_ = t_us;
    if ((t_us - stuck_since_us_) * 1e-6 < o_.stuck_s) return false;
    if (++stalls_this_goal_ > o_.max_stalls) {
      SetState("failed", "stalled " + std::to_string(stalls_this_goal_) + " times on the way to one goal", t_us);
      Send(0, 0, t_us);
      return true;
    }
    ++recoveries_;
    mbot::log::Warn("mission: stalled for " + Num(o_.stuck_s, 3) + " s while commanded to move: backing off");
    stuck_since_us_ = -1;
    last_command_ = {};
    backoff_until_us_ = t_us + static_cast<int64_t>(o_.backoff_s * 1e6);
    last_explore_us_ = -1;  // replan as soon as the back-off ends
    if (o_.task == Task::kWarehouse && final_leg_) need_plan_ = true;
    Send(-0.1, 0.0, t_us);
    return true;
  }

  // At the final pose (goal_): the controller has stopped commanding, but the wheels lag, so wait
  // until the robot stands still, then check the pose; outside the tolerances, drive to it again.
  // True once it stands at the goal (or the corrections are spent); *how says how well.
  bool Settled(const Pose2D& pose, int64_t t_us, std::string* how) {
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
      *how = std::to_string(corrections_) + " corrections; off by " + Num(d, 3) + " m, " + Num(e * 180 / M_PI, 3) +
             " deg by its own estimate";
      return true;
    }
    ++corrections_, ++total_corrections_;
    const bool publish = o_.task != Task::kFollow;
    if (!heading_ok && d <= kTurnOnlyWithin * o_.controller.final_tolerance_m) {
      SetPath({Pose2D{pose.x, pose.y, goal_.theta}}, t_us, publish);
    } else {
      SetPath({goal_}, t_us, publish);
    }
    return false;
  }

  // The Warehouse: stand still until global localization has settled, then drive to each stop in
  // turn (A* on the known map), stand there for dwell_s, and go on. False when it has already
  // commanded the robot this step (standing still).
  bool WarehouseStep(const Pose2D& pose, int64_t t_us) {
    if (slam_status_.state != "localized") {
      SetState("localizing", "waiting for SLAM to localize (it says " +
                                 (slam_status_.state.empty() ? std::string("nothing yet") : slam_status_.state) + ")", t_us);
      if (final_leg_) need_plan_ = true;  // the path was planned from a pose no longer trusted
      Send(0, 0, t_us);
      return false;
    }
    if (!planner_.has_map()) {
      if (!map_) {
        SetState("localizing", "waiting for the known map", t_us);
        Send(0, 0, t_us);
        return false;
      }
      planner_.SetMap(planning::ObstacleDistanceGrid(*map_, o_.exploration.distance));
    }
    if (dwell_until_us_ >= 0) {
      if (t_us < dwell_until_us_) {
        Send(0, 0, t_us);
        return false;
      }
      dwell_until_us_ = -1;
      if (++stop_index_ == stops_.size()) {
        SetState("completed", "stood at all " + std::to_string(stops_.size()) + " targets and drop-offs by its own estimate", t_us);
        Send(0, 0, t_us);
        return false;
      }
      need_plan_ = true;
    }
    if (need_plan_ && t_us >= backoff_until_us_) {
      const warehouse::Stop& stop = stops_[stop_index_];
      const planning::PlanResult r = planner_.PlanSteppingOut(pose, stop.pose);
      if (r.status != planning::PlanStatus::kFound) {
        SetState("failed", "no path to " + stop.Name() + ": " + planning::ToString(r.status), t_us);
        Send(0, 0, t_us);
        return false;
      }
      need_plan_ = false;
      goal_ = stop.pose;
      final_leg_ = true;
      corrections_ = 0;
      SetPath(r.path, t_us);
      SetState("driving", "to " + stop.Name() + " of " + std::to_string(warehouse::TotalDeliveries()), t_us);
    }
    return true;
  }

  // Follow: drive each path a GUI sends on path_channel (the latest replaces the one being driven);
  // between paths, stand still. False when it has already commanded the robot this step.
  bool FollowStep(int64_t t_us) {
    if (!gui_path_.empty()) {
      goal_ = gui_path_.back();
      final_leg_ = true;
      corrections_ = 0;
      SetPath(gui_path_, t_us, /*publish=*/false);
      SetState("driving", "a path of " + std::to_string(gui_path_.size()) + " poses from " + o_.path_channel, t_us);
      gui_path_.clear();
    }
    if (final_leg_) return true;
    if (state_ != "arrived") SetState("waiting", "for a path on " + o_.path_channel, t_us);
    Send(0, 0, t_us);
    return false;
  }

  // The goal is reached and the robot stands at it.
  void Arrived(const std::string& how, int64_t t_us) {
    final_leg_ = false;
    if (o_.task == Task::kFollow) {
      SetState("arrived", "at the end of the path (" + how + ")", t_us);
      return;
    }
    if (o_.task != Task::kWarehouse) {
      SetState("completed", std::string(o_.task == Task::kWaypoints ? "circuit driven" : "explored and home") + " (" + how + ")", t_us);
      return;
    }
    const warehouse::Stop& stop = stops_[stop_index_];
    dwell_until_us_ = t_us + static_cast<int64_t>(o_.dwell_s * 1e6);
    SetState(stop.pickup ? "lifting" : "setting_down", "at " + stop.Name() + " (" + how + ")", t_us);
  }

  // Body velocity from odometry over the last 0.1 s.
  motion::VelocityCommand MeasuredVelocity() const {
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
  Pose2D Predict(const Pose2D& pose) const {
    if (o_.control_lag_s <= 0) return pose;
    return motion::StepUnicycle(pose, MeasuredVelocity(), o_.control_lag_s);
  }

  void SetState(const std::string& state, const std::string& detail, int64_t t_us) {
    if (state == state_ && detail == detail_) return;
    state_ = state, detail_ = detail;
    mbot::log::Info("mission: " + state + (detail.empty() ? "" : " (" + detail + ")"));
    if (bus_) bus_->Emit(this, drivers::Event{t_us, t_us, o_.status_channel, EventKind::kStatus, drivers::Status{state, detail}});
  }

  // `publish`: the path goes out on CONTROLLER_PATH (not for a path that came in on it).
  void SetPath(const std::vector<Pose2D>& path, int64_t t_us, bool publish = true) {
    // A new goal (not a replan or a correction towards the same one) gets a fresh stall budget.
    if (!path.empty() && std::hypot(path.back().x - stall_goal_.x, path.back().y - stall_goal_.y) > kSameGoalM) {
      stall_goal_ = path.back();
      stalls_this_goal_ = 0;
    }
    controller_.SetPath(path);
    ++paths_;
    if (bus_ && publish) bus_->Emit(this, drivers::Event{t_us, t_us, o_.path_channel, EventKind::kPath, drivers::Path{path}});
  }

  void Send(double v, double w, int64_t t_us) {
    ++commands_;
    if (bus_) {
      bus_->Emit(this, drivers::Event{t_us, t_us, "MBOT_VEL_CMD", EventKind::kMotorCommand,
                                      drivers::MotorCommand{drivers::MotorCommand::Kind::kVelocity, v, w}});
    }
  }

  void Control(int64_t t_us) {
    const double dt = last_control_us_ >= 0 ? (t_us - last_control_us_) * 1e-6 : 0.0;
    last_control_us_ = t_us;
    Pose2D pose;
    if (!PoseNow(&pose) || (t_us - first_slam_us_) * 1e-6 < o_.start_delay_s) {
      SetState("initializing", "waiting for SLAM", t_us);
      Send(0, 0, t_us);
      return;
    }
    if ((t_us - slam_.t_us) * 1e-6 > o_.max_pose_age_s) {
      ++stale_stops_;
      SetState(state_, "SLAM pose stale: stopped", t_us);
      Send(0, 0, t_us);
      return;
    }
    if ((state_ == "completed" || state_ == "failed") && !(o_.task == Task::kFollow && !gui_path_.empty())) {
      Send(0, 0, t_us);  // done (follow: until the next path, which a failure does not end)
      return;
    }
    if (o_.task == Task::kWaypoints) {
      if (!started_) {
        started_ = true;
        goal_ = o_.waypoints.back();
        final_leg_ = true;
        SetPath(o_.waypoints, t_us);
        SetState("driving", "circuit of " + std::to_string(o_.waypoints.size()) + " waypoints", t_us);
      }
    } else if (o_.task == Task::kExplore && !explored_ && map_ &&
               (last_explore_us_ < 0 || (t_us - last_explore_us_) * 1e-6 >= o_.explore_period_s)) {
      last_explore_us_ = t_us;
      const planning::ExplorationUpdate u = explorer_.Update(*map_, pose, t_us * 1e-6);
      if (u.state == planning::ExplorationState::kFailed) {
        SetState("failed", explorer_.failure_reason(), t_us);
        Send(0, 0, t_us);
        return;
      }
      if (u.new_path || u.state == planning::ExplorationState::kCompleted) {
        // Home is a pose: the way back ends in the heading the robot started with.
        std::vector<Pose2D> path = u.path;
        if (u.state == planning::ExplorationState::kCompleted) path = {explorer_.home()};
        if (u.state != planning::ExplorationState::kExploring && !path.empty()) path.back().theta = explorer_.home().theta;
        SetPath(path, t_us);
      }
      if (u.state == planning::ExplorationState::kCompleted) {
        explored_ = true;  // at home: the controller settles the final pose, then the mission is complete
        goal_ = explorer_.home();
        final_leg_ = true;
        SetState("returning_home", "aligning at home", t_us);
      } else {
        SetState(planning::ToString(u.state), u.reason, t_us);
      }
    } else if (o_.task == Task::kWarehouse && !WarehouseStep(pose, t_us)) {
      return;
    } else if (o_.task == Task::kFollow && !FollowStep(t_us)) {
      return;
    }
    if (Recovering(t_us)) return;
    const motion::VelocityCommand c = controller_.Update(Predict(pose), dt);
    Send(c.v_m_s, c.w_rad_s, t_us);
    last_command_ = c;
    std::string how;
    if (final_leg_ && controller_.arrived() && Settled(pose, t_us, &how)) Arrived(how, t_us);
  }

  MissionOptions o_;
  motion::MotionController controller_;
  planning::Explorer explorer_;
  Bus* bus_ = nullptr;
  TimedPose slam_;
  bool has_slam_ = false;
  int64_t first_slam_us_ = -1, last_control_us_ = -1, last_explore_us_ = -1;
  std::vector<TimedPose> odometry_;  // the last ~5 s
  std::shared_ptr<const mapping::OccupancyGrid> map_;
  bool started_ = false;
  bool explored_ = false;  // the explorer is done; the controller finishes at home
  bool final_leg_ = false;  // the path ends at goal_, where the robot must stop within the tolerances
  Pose2D goal_;
  drivers::Status slam_status_;
  // Follow: a path received and not yet taken.
  std::vector<Pose2D> gui_path_;
  // Warehouse.
  std::vector<warehouse::Stop> stops_;
  size_t stop_index_ = 0;
  planning::AStarPlanner planner_;
  bool need_plan_ = true;
  int64_t dwell_until_us_ = -1;
  Pose2D stall_goal_{1e9, 1e9, 0};  // the goal the stall budget is for
  std::string state_ = "initializing", detail_;
  long long commands_ = 0, paths_ = 0, stale_stops_ = 0;
  int corrections_ = 0, total_corrections_ = 0, recoveries_ = 0, stalls_this_goal_ = 0;
  motion::VelocityCommand last_command_;
  int64_t stuck_since_us_ = -1, backoff_until_us_ = 0;
};

}  // namespace

StageType MissionStageType() {
  return {"mission",
          "the autonomy after SLAM: follows a circuit of waypoints or explores and returns home (A* + frontiers), "
          "driving the motion controller; emits velocity commands, paths and states",
          [](config::Section& s) -> std::unique_ptr<Stage> {
            MissionOptions o;
            const std::string task = s.GetChoice("task", "waypoints", {"waypoints", "explore", "warehouse", "follow"},
                                                 "follow a circuit of waypoints, explore the unknown and return home, make "
                                                 "the Warehouse's deliveries in the known map (the arena's targets and drop-offs), "
                                                 "or drive the paths a GUI sends on path_channel");
            o.task = task == "explore"     ? Task::kExplore
                     : task == "warehouse" ? Task::kWarehouse
                     : task == "follow"    ? Task::kFollow
                                           : Task::kWaypoints;
            const std::vector<std::string> w =
                s.GetList("waypoints", {"arena"},
                          "the circuit: 'arena' (the simulated arena's waypoint poses, relative to its start pose) or "
                          "x, y, theta_deg triples in the start frame");
            if (!(w.size() == 1 && w[0] == "arena")) {
              o.waypoints_from_arena = false;
              if (w.size() % 3 != 0 || w.empty()) s.Fail("waypoints", "expected x, y, theta_deg triples or 'arena'");
              for (size_t i = 0; i + 2 < w.size(); i += 3) {
                try {
                  o.waypoints.push_back({std::stod(w[i]), std::stod(w[i + 1]), std::stod(w[i + 2]) * M_PI / 180.0});
                } catch (const std::exception&) {
                  s.Fail("waypoints", "'" + w[i] + ", " + w[i + 1] + ", " + w[i + 2] + "' is not three numbers");
                }
              }
            }
            auto& c = o.controller;
            c.kind = s.GetChoice("controller", "rotate_translate_rotate", {"rotate_translate_rotate", "pure_pursuit"},
                                 "waypoint controller") == "pure_pursuit"
                         ? motion::ControllerKind::kPurePursuit
                         : motion::ControllerKind::kRotateTranslateRotate;
            c.max_speed_m_s = s.GetDouble("max_speed_m_s", c.max_speed_m_s, "speed limit [m/s]", 0.01, 2.0);
            c.max_turn_rate_rad_s = s.GetDouble("max_turn_rate_rad_s", c.max_turn_rate_rad_s, "turn-rate limit [rad/s]", 0.05, 10.0);
            c.max_accel_m_s2 = s.GetDouble("max_accel_m_s2", c.max_accel_m_s2, "acceleration limit [m/s^2]", 0.01, 10.0);
            c.max_angular_accel_rad_s2 = s.GetDouble("max_angular_accel_rad_s2", c.max_angular_accel_rad_s2,
                                                     "angular acceleration limit [rad/s^2]", 0.1, 100.0);
            c.final_tolerance_m = s.GetDouble("final_tolerance_m", c.final_tolerance_m, "arrival tolerance at the last waypoint [m]", 0.001, 1.0);
            c.intermediate_tolerance_m = s.GetDouble("intermediate_tolerance_m", c.intermediate_tolerance_m,
                                                     "an intermediate waypoint counts as passed this close [m]", 0.001, 2.0);
            c.final_heading_tolerance_rad = s.GetDouble("final_heading_tolerance_rad", c.final_heading_tolerance_rad,
                                                        "heading tolerance at the last waypoint [rad]", 0.001, 3.2);
            c.lookahead_m = s.GetDouble("lookahead_m", c.lookahead_m, "pure pursuit look-ahead [m]", 0.01, 5.0);
            c.reverse_within_m = s.GetDouble("reverse_within_m", c.reverse_within_m,
                                             "a correction to a final pose this near and behind backs up instead of turning round [m]", 0.0, 1.0);
            o.exploration = planning::ParseExplorationOptions(s);
            o.explore_period_s = s.GetDouble("explore_period_s", o.explore_period_s, "explorer updates at most this often [s]", 0.0, 60.0);
            o.start_delay_s = s.GetDouble("start_delay_s", o.start_delay_s, "stand still this long after the first SLAM pose [s]", 0.0, 60.0);
            o.max_pose_age_s = s.GetDouble("max_pose_age_s", o.max_pose_age_s, "stop when the SLAM pose is older than this [s]", 0.01, 60.0);
            o.control_lag_s = s.GetDouble("control_lag_s", o.control_lag_s,
                                          "the controller sees the pose predicted this far ahead (the wheels' response lag) [s]", 0.0, 2.0);
            o.max_corrections = static_cast<int>(s.GetInt("max_corrections", o.max_corrections,
                                                          "times the final pose is driven to again when the robot stopped outside the tolerances", 0, 100));
            o.stuck_s = s.GetDouble("stuck_s", o.stuck_s, "commanded to move but stalled this long: back off [s]", 0.1, 60.0);
            o.max_stalls = static_cast<int>(s.GetInt("max_stalls", o.max_stalls, "stalls on the way to one goal before the mission fails", 0, 100000));
            o.backoff_s = s.GetDouble("backoff_s", o.backoff_s, "how long to reverse at 0.1 m/s when stalled [s]", 0.0, 10.0);
            o.dwell_s = s.GetDouble("dwell_s", o.dwell_s, "warehouse: how long to stand at a target or drop-off [s] (the rules ask " +
                                    Num(warehouse::kDwellS, 3) + " s)", 0.0, 600.0);
            o.status_channel = s.GetString("status_channel", o.status_channel, "channel of the status events");
            o.path_channel = s.GetString("path_channel", o.path_channel,
                                         "paths go out here; with task = follow, a GUI's paths come in here");
            o.slam_status_channel = s.GetString("slam_status_channel", o.slam_status_channel,
                                                "channel of SLAM's status (warehouse: drive only once it says localized)");
            return std::make_unique<MissionStage>(o);
          }};
}

}  // namespace mbot::app
