// The Heavy Lift task, in its phases (libs/mission/src/heavy_lift/): heavy_lift_task.cpp holds the
// task's frame (sightings, the phase switch, arrivals, stalls); search.cpp finds a crate and plans
// to a stand-off before one of its faces; approach.cpp looks, lines up and drives the tines in (or
// the carried crate over the other); lift.cpp lifts and sets down; out.cpp backs off and goes home.
//
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
#pragma once

#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <memory>
#include <string>

#include "../tasks.hpp"
#include "mbot/planning/astar.hpp"

namespace mbot::mission::heavy_lift {

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

  void TagsSeen(Mission& m, const Pose2D& pose, const std::vector<TagSeen>& tags) override;
  bool Step(Mission& m, const Pose2D& pose) override;
  void Arrived(Mission& m, const std::string& how) override;
  void Stalled(Mission& m) override;
  void AddToReport(MissionReport* r) const override;

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
  void Fork(Mission& m, double height_m);
  void Fail(Mission& m, const std::string& why);
  // The planner on the latest map; false (holding) while there is none.
  bool PlannerReady(Mission& m);
  // A crate not seen yet: it may be hidden behind another or too far to read. Turn on the spot,
  // then go round the crates seen (the day's crates to lift stand in one area): a viewpoint 0.8 m
  // from their centre, first on the robot's side, then a quarter turn round either way, then the
  // far side; a turn on the spot at each.
  bool Search(Mission& m, const Pose2D& pose);
  bool Find(Mission& m, const Pose2D& pose);
  // At the stand-off: look, refine, and either go in or line up again.
  bool Look(Mission& m, const Pose2D& pose);
  // Drive along line_ (forward or back) to `end` along it, steering onto it; true once there or
  // stopped (no progress for a second: the tines are fully in, or something is in the way).
  bool FollowLine(Mission& m, const Pose2D& pose, double end, bool forward);
  bool In(Mission& m, const Pose2D& pose);
  bool Lift(Mission& m);
  bool SetDown(Mission& m);
  void StartOut(Mission& m, const std::string& what);
  bool Out(Mission& m, const Pose2D& pose);

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

}  // namespace mbot::mission::heavy_lift
