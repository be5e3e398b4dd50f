// Heavy Lift: one turn on the spot to see the crates; then for each (crate, crate to stack it on) of
// the day, in order — find the crate by its tag (one not seen yet is looked for from round the
// crates seen), drive (A* with SLAM) to a stand-off square to one of its faces, look (fresh
// sightings refine where the crate is), line up, drive the tines in along the face's normal by
// servoing on the crate's estimated pose, lift, back off; then the same to the crate it goes on,
// with the carried crate held above it, set it down, back off. Home at the end.
//
// Where a crate is comes from the camera only: each sighting (tag centre and facing, robot frame,
// at the frame's time) is put in the map frame with the robot's pose then, and the crate's centre
// and heading (modulo 90 degrees: a crate's four faces are alike) are the weighted mean of its last
// sightings, nearer ones weighing more (a tag's pose error grows with its range). Close to a face
// the tag leaves the camera's view (and a carried crate hides what is ahead), so the last part of
// each approach servos on the estimate made while it was in view.
#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <string>

#include "mbot/common/log.hpp"
#include "mbot/common/strings.hpp"
#include "mbot/planning/astar.hpp"
#include "tasks.hpp"

namespace mbot::mission {
namespace {

using motion::Pose2D;

constexpr double kQuarter = 0.5 * M_PI;

// The crate's centre and heading (mod 90°) in the map frame from its recent sightings.
class CrateEstimate {
 public:
  void Add(double x, double y, double yaw, double range, int64_t t_us) {
    seen_.push_back({x, y, yaw, 1.0 / std::max(range * range, 0.04), t_us});
    if (seen_.size() > 15) seen_.pop_front();
  }
  bool known() const { return !seen_.empty(); }
  int SeenSince(int64_t t_us) const {
    return static_cast<int>(std::count_if(seen_.begin(), seen_.end(), [&](const S& s) { return s.t_us >= t_us; }));
  }
  // Forget sightings from before t_us (the crate was moved then).
  void ForgetBefore(int64_t t_us) {
    while (!seen_.empty() && seen_.front().t_us < t_us) seen_.pop_front();
  }
  // The centre, and the heading in [−45°, 45°).
  Pose2D Get() const {
    double x = 0, y = 0, c = 0, s = 0, w = 0;
    for (const S& e : seen_) {
      x += e.w * e.x, y += e.w * e.y, w += e.w;
      c += e.w * std::cos(4 * e.yaw), s += e.w * std::sin(4 * e.yaw);
    }
    return {x / w, y / w, std::atan2(s, c) / 4};
  }

 private:
  struct S {
    double x, y, yaw, w;
    int64_t t_us;
  };
  std::deque<S> seen_;
};

enum class Phase {
  kStart,
  kSurvey,       // one turn on the spot at the start: see every crate around
  kToViewpoint,  // A* to a place to look for a crate not seen yet
  kFind,         // plan to a stand-off before the crate of the step (look for it first if unseen)
  kToStandOff,   // A* to the stand-off before a face
  kLook,         // stand still, gather sightings, check the line-up
  kIn,           // servo along the face's normal: tines in (pick) or carried crate over (place)
  kLift,         // tines up: the crate is lifted
  kSetDown,      // tines down: the crate is set on the other
  kOut,          // back off along the line
  kHome,
  kDone,
};

class HeavyLiftTask : public Task {
 public:
  explicit HeavyLiftTask(const MissionOptions& o)
      : o_(o.heavy_lift), planner_(o.exploration.astar), distance_(o.exploration.distance) {
    if (o_.stack.empty()) throw std::invalid_argument("task heavy_lift: no crates to stack (key stack)");
  }

  void TagsSeen(Mission& m, const Pose2D& pose, const std::vector<TagSeen>& tags) override {
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

  bool Step(Mission& m, const Pose2D& pose) override {
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

  void Arrived(Mission& m, const std::string& how) override {
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
                                               " crates set down on their crates by the forklift's report; home (" +
                                               how + ")");
      return;
    }
    phase_ = Phase::kLook;
    phase_us_ = m.now_us();
  }

  void Stalled(Mission& m) override {
    if (phase_ == Phase::kToViewpoint) --viewpoint_;  // that viewpoint again, from where the back-off ends
    if (phase_ == Phase::kToStandOff || phase_ == Phase::kToViewpoint) {
      phase_ = Phase::kFind;  // plan again from where the back-off ends
      phase_us_ = m.now_us();
    }
  }

  void AddToReport(MissionReport* r) const override {
    r->crates = static_cast<int>(o_.stack.size());
    r->crates_lifted = lifted_;
    r->crates_set_down = stacked_;
    r->tag_sightings = sightings_;
  }

 private:
  bool picking() const { return carried_ < 0; }
  int target() const { return picking() ? o_.stack[job_].first : o_.stack[job_].second; }
  std::string Name() const {
    return (picking() ? "crate " : "crate " + std::to_string(carried_) + " onto crate ") + std::to_string(target());
  }
  // Where the robot's centre stands, square to a face of the crate at `c` whose outward normal is
  // `normal`, `gap` before it: for picking, the tips `gap` from the face; for placing, the carried
  // crate's centre `gap` short of the crate's centre.
  Pose2D StandOff(const Pose2D& c, double normal, double gap) const {
    const double reach = picking() ? 0.5 * o_.crate_side_m + o_.fork_tip_x_m + gap : carry_offset_ + gap;
    return {c.x + reach * std::cos(normal), c.y + reach * std::sin(normal), motion::WrapAngle(normal + M_PI)};
  }
  // The face towards the robot (of the four), as the heading of its outward normal.
  static double FaceTowards(const Pose2D& c, const Pose2D& pose) {
    const double bearing = std::atan2(pose.y - c.y, pose.x - c.x);
    return c.theta + kQuarter * std::round(motion::WrapAngle(bearing - c.theta) / kQuarter);
  }

  // The tines to `height_m`: commanded once (again only when it changes).
  void Fork(Mission& m, double height_m) {
    if (height_m == fork_cmd_) return;
    fork_cmd_ = height_m;
    m.CommandFork(height_m);
  }

  void Fail(Mission& m, const std::string& why) {
    phase_ = Phase::kDone;
    m.SetState(MissionState::kFailed, why);
    m.Hold();
  }

  // The planner on the latest map; false (holding) while there is none.
  bool PlannerReady(Mission& m) {
    if (!m.map()) return false;
    if (!planner_.has_map() || planned_map_ != m.map()) {
      planner_.SetMap(planning::ObstacleDistanceGrid(*m.map(), distance_));
      planned_map_ = m.map();
    }
    return true;
  }

  // A crate not seen yet: it may be hidden behind another or too far to read. Turn on the spot,
  // then go round the crates seen (the day's crates to lift stand in one area): a viewpoint 0.8 m
  // from their centre, first on the robot's side, then a quarter turn round either way, then the
  // far side; a turn on the spot at each.
  bool Search(Mission& m, const Pose2D& pose) {
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

  bool Find(Mission& m, const Pose2D& pose) {
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

  // At the stand-off: look, refine, and either go in or line up again.
  bool Look(Mission& m, const Pose2D& pose) {
    m.Hold();
    const CrateEstimate& e = crates_[target()];
    if (!picking()) {
      // Up to the stacking height first (the carried crate then clears the other's top).
      Fork(m, o_.stack_height_m);
      const std::optional<ForkliftState>& f = m.forklift();
      if (!f || std::abs(f->height_m - o_.stack_height_m) > 0.003) {
        phase_us_ = m.now_us();
        return false;
      }
    }
    if ((m.now_us() - phase_us_) * 1e-6 < o_.look_s) return false;
    const Pose2D c = e.Get();
    normal_ = c.theta + kQuarter * std::round(motion::WrapAngle(normal_ - c.theta) / kQuarter);
    const double gap = picking() ? o_.standoff_m : o_.place_standoff_m;
    const Pose2D goal = StandOff(c, normal_, gap);
    const Pose2D off = goal.Inverse().Compose(pose);
    const bool lined_up = std::abs(off.y) <= o_.align_lateral_m &&
                          std::abs(off.theta) <= o_.align_heading_deg * M_PI / 180 && std::abs(off.x) <= 0.05;
    if (!lined_up && realigns_ < 3) {
      ++realigns_;
      m.SetGoal(goal);
      m.SetPath({goal});
      m.SetState(MissionState::kDriving, "lining up with " + Name() + " (off by " + Significant(off.y * 100, 2) +
                                             " cm, " + Significant(off.theta * 180 / M_PI, 2) + " deg)");
      phase_ = Phase::kToStandOff;
      return false;
    }
    realigns_ = 0;
    line_ = goal;
    // Picking: the tips to insert_depth past the face. Placing: the carried crate over the other.
    line_end_ = gap + (picking() ? o_.insert_depth_m : 0.0);
    m.SetState(picking() ? MissionState::kLifting : MissionState::kSettingDown,
               (picking() ? "tines into " : "carrying ") + Name());
    phase_ = Phase::kIn;
    phase_us_ = m.now_us();
    progress_ = {m.now_us(), -1e9};
    return false;
  }

  // Drive along line_ (forward or back) to `end` along it, steering onto it; true once there or
  // stopped (no progress for a second: the tines are fully in, or something is in the way).
  bool FollowLine(Mission& m, const Pose2D& pose, double end, bool forward) {
    const Pose2D d = line_.Inverse().Compose(pose);
    const double sign = forward ? 1.0 : -1.0;
    if (sign * (d.x - end) >= 0) return true;
    if (std::abs(d.x - progress_.second) > 0.002) progress_ = {m.now_us(), d.x};
    if ((m.now_us() - progress_.first) * 1e-6 > 1.0) return true;
    const double want = -sign * std::atan(10.0 * d.y) * 0.5;  // heading that brings it back onto the line
    const double w = std::clamp(3.0 * motion::WrapAngle(want - d.theta), -0.6, 0.6);
    const double v = sign * std::min(o_.approach_speed_m_s, 0.02 + 0.5 * std::abs(d.x - end));
    m.Drive(v, w);
    return false;
  }

  bool In(Mission& m, const Pose2D& pose) {
    if (!FollowLine(m, pose, line_end_, true)) return false;
    m.Hold();
    phase_ = picking() ? Phase::kLift : Phase::kSetDown;
    phase_us_ = m.now_us();
    Fork(m, picking() ? o_.carry_height_m : 0.0);
    inserted_ = std::hypot(pose.x - line_.x, pose.y - line_.y) - o_.standoff_m;
    return false;
  }

  bool Lift(Mission& m) {
    m.Hold();
    const std::optional<ForkliftState>& f = m.forklift();
    const bool up = f && std::abs(f->height_m - o_.carry_height_m) < 0.003;
    if (f && f->carrying && f->crate_id == target() && up) {
      ++lifted_;
      carried_ = target();
      carry_offset_ = o_.fork_tip_x_m - std::max(inserted_, 0.0) + 0.5 * o_.crate_side_m;
      crates_[carried_].ForgetBefore(m.now_us() + 1);  // it moves with the robot now
      StartOut(m, "lifted " + std::to_string(carried_));
    } else if (up || (m.now_us() - phase_us_) * 1e-6 > 10.0) {
      // Up without it: the tines missed the slot. Down, back off, try again.
      Fork(m, 0.0);
      if (++attempts_ >= o_.max_attempts) {
        Fail(m, "could not engage " + Name() + " in " + std::to_string(attempts_) + " tries");
        return false;
      }
      StartOut(m, "missed " + Name() + "; backing off to try again");
    }
    return false;
  }

  bool SetDown(Mission& m) {
    m.Hold();
    const std::optional<ForkliftState>& f = m.forklift();
    if (f && !f->carrying) {
      ++stacked_;
      just_set_down_ = true;
      crates_[carried_].ForgetBefore(m.now_us() + 1);  // where it is now: to be seen again
      carried_ = -1;
      StartOut(m, "set down");
    } else if ((m.now_us() - phase_us_) * 1e-6 > 10.0) {
      Fail(m, "the forklift still carries " + std::to_string(carried_) + " 10 s after lowering");
    }
    return false;
  }

  void StartOut(Mission& m, const std::string& what) {
    line_ = {};
    phase_ = Phase::kOut;
    phase_us_ = m.now_us();
    progress_ = {m.now_us(), -1e9};
    m.SetState(MissionState::kDriving, what + ": backing off");
    out_started_ = false;
  }

  bool Out(Mission& m, const Pose2D& pose) {
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

  HeavyLiftOptions o_;
  planning::AStarPlanner planner_;
  planning::ObstacleDistanceOptions distance_;
  std::shared_ptr<const mapping::OccupancyGrid> planned_map_, failed_map_;
  std::map<int, CrateEstimate> crates_;
  Phase phase_ = Phase::kStart;
  int64_t phase_us_ = 0;
  size_t job_ = 0;    // the step of o_.stack being done
  int carried_ = -1;  // the crate on the tines
  int lifted_ = 0, stacked_ = 0, attempts_ = 0, realigns_ = 0;
  long long sightings_ = 0;
  double normal_ = 0;        // the face worked on: its outward normal's heading
  Pose2D line_;              // the approach line: the stand-off pose
  double line_end_ = 0;      // how far along it to go
  double inserted_ = 0;      // how far past the face the tips went
  double carry_offset_ = 0;  // the carried crate's centre ahead of the robot's
  std::pair<int64_t, double> progress_;
  bool out_started_ = false, just_set_down_ = false;
  int64_t no_path_since_us_ = -1;
  int viewpoint_ = 0;                   // viewpoints tried while looking for the crate of this step
  double fork_cmd_ = -1;                // the tines' height commanded last
  double turned_ = 0, last_theta_ = 0;  // turning on the spot: how far so far, the heading last step
  bool turn_from_here_ = false;
  Pose2D home_;
};

}  // namespace

std::unique_ptr<Task> MakeHeavyLiftTask(const MissionOptions& options) {
  return std::make_unique<HeavyLiftTask>(options);
}

}  // namespace mbot::mission
