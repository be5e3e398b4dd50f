#include "mbot/sim/referee.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "mbot/common/log.hpp"
#include "mbot/common/strings.hpp"

namespace mbot::sim {
namespace {

namespace warehouse = mission::warehouse;
using motion::Pose2D;
using motion::TimedPose;

std::string Errors(const PoseError& e) {
  char b[80];
  std::snprintf(b, sizeof b, "%.3f / %.3f m, %.1f deg", e.x_m, e.y_m, e.theta_deg);
  return b;
}

PoseError ErrorBetween(const Pose2D& a, const Pose2D& b) {
  return {std::abs(a.x - b.x), std::abs(a.y - b.y), std::abs(motion::WrapAngle(a.theta - b.theta)) * 180.0 / M_PI};
}

}  // namespace

const char* ToString(CompetitionEvent event) {
  switch (event) {
    case CompetitionEvent::kSpeedRun: return "speed_run";
    case CompetitionEvent::kMazeExplorer: return "maze_explorer";
    case CompetitionEvent::kWarehouse: return "warehouse";
    case CompetitionEvent::kHeavyLift: return "heavy_lift";
  }
  return "?";
}

const char* Title(CompetitionEvent event) {
  switch (event) {
    case CompetitionEvent::kSpeedRun: return "Speed Run";
    case CompetitionEvent::kMazeExplorer: return "Maze Explorer";
    case CompetitionEvent::kWarehouse: return "Warehouse";
    case CompetitionEvent::kHeavyLift: return "Heavy Lift";
  }
  return "?";
}

int PosePoints(const PoseError& e) {
  struct Tier {
    double xy, th;
    int points;
  };
  for (const Tier& t : {Tier{0.03, 15, 100}, Tier{0.05, 15, 75}, Tier{0.10, 30, 50}, Tier{0.20, 45, 25}}) {
    if (e.x_m < t.xy && e.y_m < t.xy && e.theta_deg < t.th) return t.points;
  }
  return 0;
}

int LapPoints(double s) { return s < 15 ? 100 : s < 20 ? 75 : s < 30 ? 50 : 0; }

ReachableCells FindReachableCells(const World& world, const Pose2D& start, double robot_radius_m) {
  ReachableCells r;
  r.start = start;
  const mapping::OccupancyGrid& truth = world.truth();
  const std::vector<uint8_t> reach = BodyReachableMask(world, start, robot_radius_m);
  for (int cy = 0; cy < truth.height(); ++cy) {
    for (int cx = 0; cx < truth.width(); ++cx) {
      if (!reach[static_cast<size_t>(cy) * truth.width() + cx]) continue;
      double x, y;
      truth.CellToWorld(cx, cy, &x, &y);
      r.x.push_back(x);
      r.y.push_back(y);
      r.clearance.push_back(world.ClearanceAt(x, y));
    }
  }
  return r;
}

MapQuality Quality(const World& world, const mapping::OccupancyGrid& m, const ReachableCells& reachable) {
  MapQuality q;
  const Pose2D& start = reachable.start;
  const Pose2D inv = start.Inverse();
  // The free space that must be mapped keeps 1.5 map cells from the walls, the tolerance the wall
  // check below gives: a wall mapped up to 1.5 cells off counts as right, so the space it may cover
  // is not counted as missed. (A wall's cell reaches up to a cell beyond its surface, and range
  // noise spills hits into the next cell where the surface lies near a cell boundary: with 1 cm of
  // lidar noise those cells are saturated walls, which one cell of tolerance alone scored as missed.)
  // The share at one cell is kept beside it.
  int mapped = 0, counted_strict = 0, mapped_strict = 0;
  for (size_t i = 0; i < reachable.x.size(); ++i) {
    const double clearance = reachable.clearance[i];
    if (clearance < m.resolution()) continue;
    const Pose2D p = inv.Compose(Pose2D{reachable.x[i], reachable.y[i], 0});
    int mx, my;
    m.WorldToCell(p.x, p.y, &mx, &my);
    const bool free = m.IsInside(mx, my) && m.at(mx, my) < 0;
    ++counted_strict;
    mapped_strict += free;
    if (clearance < 1.5 * m.resolution()) continue;
    ++q.reachable_cells;
    if (free) {
      ++mapped;
    } else {
      q.unmapped.push_back(p);
    }
  }
  q.coverage = q.reachable_cells ? double(mapped) / q.reachable_cells : 0.0;
  q.coverage_one_cell = counted_strict ? double(mapped_strict) / counted_strict : 0.0;
  int near_wall = 0;
  for (int cy = 0; cy < m.height(); ++cy) {
    for (int cx = 0; cx < m.width(); ++cx) {
      if (m.at(cx, cy) <= 0) continue;
      ++q.occupied_cells;
      double x, y;
      m.CellToWorld(cx, cy, &x, &y);
      const Pose2D w = start.Compose(Pose2D{x, y, 0});
      if (world.ClearanceAt(w.x, w.y) <= 1.5 * m.resolution()) ++near_wall;
    }
  }
  q.precision = q.occupied_cells ? double(near_wall) / q.occupied_cells : 0.0;
  return q;
}

Referee::Referee(const RefereeOptions& options, World world, uint64_t seed) : o_(options), world_(std::move(world)) {
  if (o_.event == CompetitionEvent::kWarehouse) {
    stops_ = warehouse::Stops(world_.PosesLabelled("target"), world_.PosesLabelled("dropoff"), seed);
  }
  if (o_.event == CompetitionEvent::kHeavyLift && world_.stacks().empty()) {
    throw std::invalid_argument("referee: Heavy Lift in '" + world_.name() +
                                "', which names no 'stack <crate> <on crate>' assignments");
  }
}

void Referee::Tick(int64_t t_us) {
  if (t0_us_ < 0) t0_us_ = t_us;
  last_us_ = t_us;
}

void Referee::OnTruePose(int64_t t_us, const Pose2D& pose) {
  truth_.push_back({t_us, pose});
  if (!stops_.empty()) JudgeStop(truth_.back());
}

void Referee::OnCollision(int64_t t_us, const Pose2D& pose) {
  collisions_.push_back({{t_us, pose}, slam_.empty() ? std::nullopt : std::optional<TimedPose>(slam_.back())});
}

void Referee::OnSlamState(int64_t t_us, mapping::SlamState state) {
  if (state == mapping::SlamState::kLocalized && localized_us_ < 0) localized_us_ = t_us;
}

void Referee::OnMissionStatus(int64_t t_us, const mission::MissionStatus& status) {
  // A final state stays: a state that is not final arriving after it is an older message that a
  // faulty link delivered late (the `mixed` run scored a completed exploration as returning_home).
  if (end_us_ >= 0 && !mission::IsFinal(status.state)) return;
  state_ = status.state, detail_ = status.detail;
  if (mission::IsFinal(status.state) && end_us_ < 0) end_us_ = t_us;
}

std::optional<std::string> Referee::StopReason(int64_t t_us) {
  if (stop_sent_) return std::nullopt;
  if (end_us_ >= 0 && (t_us - end_us_) * 1e-6 >= o_.finish_delay_s) {
    stop_sent_ = true;
    return std::string("referee: the mission ") + mission::ToString(state_);
  }
  if (t0_us_ >= 0 && (t_us - t0_us_) * 1e-6 >= o_.time_limit_s) {
    stop_sent_ = true;
    timed_out_ = true;
    return "referee: time limit of " + Significant(o_.time_limit_s, 4) + " s";
  }
  return std::nullopt;
}

// Warehouse: a stop is done when the true pose has stayed within the tolerances of it for the dwell
// time. Stops are judged in order; standing at a later stop first marks the ones before it missed
// (that delivery fails, the rest still count).
void Referee::JudgeStop(const TimedPose& truth) {
  const size_t next = stop_done_us_.size();  // stops before it are judged (done or missed)
  // Still standing where the last stop was done: a later stop at the same place (the drop-offs
  // repeat) must not count until the robot has left.
  if (!left_last_stop_ && next > 0 && stop_done_us_.back() >= 0) {
    left_last_stop_ = !warehouse::AtStop(truth.pose, stops_[next - 1].pose);
    if (!left_last_stop_) return;
  }
  int at = -1;
  for (size_t k = next; k < stops_.size() && at < 0; ++k) {
    if (warehouse::AtStop(truth.pose, stops_[k].pose)) at = static_cast<int>(k);
  }
  if (at != near_stop_) near_stop_ = at, near_since_us_ = truth.t_us;
  if (at < 0 || (truth.t_us - near_since_us_) * 1e-6 < warehouse::kDwellS) return;
  for (size_t k = next; k < static_cast<size_t>(at); ++k) {
    stop_done_us_.push_back(-1);
    mbot::log::Warn("referee: " + stops_[k].Name() + " missed");
  }
  stop_done_us_.push_back(truth.t_us);
  near_stop_ = -1;
  left_last_stop_ = false;
  mbot::log::Info("referee: " + stops_[at].Name() + " done at " + Significant((truth.t_us - t0_us_) * 1e-6, 4) + " s");
}

Score Referee::Judge() const {
  Score s;
  s.event = o_.event;
  s.state = state_, s.detail = detail_;
  s.timed_out = timed_out_;
  s.collisions = static_cast<int>(collisions_.size());
  s.sim_s = t0_us_ >= 0 ? (last_us_ - t0_us_) * 1e-6 : 0.0;
  s.completed = state_ == mission::MissionState::kCompleted;
  s.incomplete = state_ == mission::MissionState::kIncomplete;
  s.time_s = end_us_ >= 0 ? (end_us_ - t0_us_) * 1e-6 : s.sim_s;
  if (truth_.empty()) return s;
  s.scored = true;
  const bool warehouse = o_.event == CompetitionEvent::kWarehouse;
  s.start = truth_.front().pose, s.final_pose = truth_.back().pose;
  // Where the map frame lies in the world: SLAM began at the origin at the start pose, or the map
  // was given in the world frame (the Warehouse).
  s.map_frame = warehouse ? Pose2D{} : s.start;
  for (const Collision& c : collisions_) {
    CollisionRecord r{(c.truth.t_us - t0_us_) * 1e-6, c.truth.pose, std::nullopt, 0.0};
    if (const std::optional<TimedPose>& e = c.estimate) {
      r.estimate = s.map_frame.Compose(e->pose);
      r.estimate_age_s = (c.truth.t_us - e->t_us) * 1e-6;
      // Its error against the truth at its own time, not at the collision's: the robot moved between.
      Pose2D truth_then;
      if (motion::InterpolateAt(truth_, e->t_us, 200'000, &truth_then))
        r.estimate_error_m = std::hypot(r.estimate->x - truth_then.x, r.estimate->y - truth_then.y);
    }
    s.collision_events.push_back(r);
  }
  if (!slam_.empty()) {
    Pose2D truth_then;
    if (motion::InterpolateAt(truth_, slam_.back().t_us, 200'000, &truth_then)) {
      s.slam_final_error = ErrorBetween(s.map_frame.Compose(slam_.back().pose), truth_then);
    }
  }
  if (o_.event == CompetitionEvent::kHeavyLift) {
    std::vector<std::pair<int, int>> stacks = world_.stacks();
    if (o_.crates > 0 && static_cast<size_t>(o_.crates) < stacks.size()) stacks.resize(o_.crates);
    for (const auto& [id, on] : stacks) {
      CrateResult r{id, on, false, false, false, {}, 0.0};
      bool seen = false;
      for (const msgs::CrateState& c : crates_.crates) {
        if (c.id != id) continue;
        seen = true;
        r.lifted = c.lifted, r.fell = c.fell, r.final_pose = c.pose, r.final_z_m = c.z_m;
        r.stacked = !c.carried && c.on_id == on;
      }
      s.crates.push_back(r);
      const std::string name = "crate " + std::to_string(id);
      s.items.push_back({"lift " + name,
                         !seen      ? "not in the simulator's crates"
                         : r.lifted ? "lifted clear of the floor"
                                    : "never lifted",
                         r.lifted ? 50 : 0, 50});
      s.items.push_back({"stack " + name + " on " + std::to_string(on),
                         r.stacked ? "standing on crate " + std::to_string(on)
                         : r.fell  ? "set down off-centre: it fell"
                                   : "not on crate " + std::to_string(on) + " at the end",
                         r.stacked ? 50 : 0, 50});
    }
  } else if (!warehouse) {
    // Final pose against the start (the robot had to come back).
    const PoseError e = ErrorBetween(s.final_pose, s.start);
    s.final_error = e;
    // An exploration that came home with frontiers left still scores where it stopped.
    const bool home = s.completed || s.incomplete;
    s.items.push_back(
        {"final pose", Errors(e) + " from the start" + (home ? "" : " (not completed)"), home ? PosePoints(e) : 0});
    if (map_ && (!reachable_ || reachable_->start.x != s.start.x || reachable_->start.y != s.start.y ||
                 reachable_->start.theta != s.start.theta)) {
      reachable_ = FindReachableCells(world_, s.start, o_.robot_radius_m);
    }
    const MapQuality mq = map_ ? Quality(world_, *map_, *reachable_) : MapQuality{};
    s.map = mq;
    s.items.push_back(
        {"map quality",
         "coverage " + Significant(100 * mq.coverage, 3) + " %, walls " + Significant(100 * mq.precision, 3) +
             " % within 1.5 cells",
         static_cast<int>(std::floor(100.0 * std::min(1.0, std::min(mq.coverage / 0.99, mq.precision / 0.95))))});
    if (o_.event == CompetitionEvent::kSpeedRun) {
      s.items.push_back({"lap time", Significant(s.time_s, 4) + " s", s.completed ? LapPoints(s.time_s) : 0});
    } else {
      s.items.push_back({"autonomy",
                         s.completed    ? "explored and home, no help"
                         : s.incomplete ? "home, but the robot reported its exploration incomplete"
                                        : "not completed",
                         s.completed ? 100 : 0});
    }
  } else {
    if (localized_us_ >= 0) s.localized_at_s = (localized_us_ - t0_us_) * 1e-6;
    s.items.push_back({"localization",
                       s.localized_at_s
                           ? "settled in " + Significant(*s.localized_at_s, 3) + " s; at the end SLAM off by " +
                                 (s.slam_final_error ? Errors(*s.slam_final_error) : std::string("?"))
                           : "global localization never settled",
                       s.localized_at_s && s.slam_final_error ? PosePoints(*s.slam_final_error) : 0});
    for (size_t k = 0; k < stops_.size(); ++k) {
      StopResult r{stops_[k], std::nullopt, false};
      if (k < stop_done_us_.size()) {
        if (stop_done_us_[k] >= 0) r.done_at_s = (stop_done_us_[k] - t0_us_) * 1e-6;
        r.missed = stop_done_us_[k] < 0;
      }
      s.stops.push_back(r);
    }
    // A delivery is made when its target and its drop-off were both done; it counts at the drop-off.
    std::vector<double> made_at_s;
    for (size_t k = 1; k < stop_done_us_.size(); k += 2) {
      if (stop_done_us_[k - 1] >= 0 && stop_done_us_[k] >= 0) made_at_s.push_back((stop_done_us_[k] - t0_us_) * 1e-6);
    }
    int needed = 0;
    for (size_t l = 0; l < warehouse::Levels().size(); ++l) {
      const warehouse::Level& level = warehouse::Levels()[l];
      needed += level.deliveries;
      const int in_time = static_cast<int>(
          std::count_if(made_at_s.begin(), made_at_s.end(), [&](double t) { return t <= level.deadline_s; }));
      // Levels are climbed in order: a level counts when the ones below it did.
      const bool reached = in_time >= needed && s.levels_reached == static_cast<int>(l);
      if (reached) s.levels_reached = static_cast<int>(l) + 1;
      s.items.push_back({"level " + std::to_string(l + 1),
                         std::to_string(std::min(in_time, needed)) + " of " + std::to_string(needed) +
                             (needed == 1 ? " delivery" : " deliveries") + " by " + Significant(level.deadline_s, 4) +
                             " s" + (reached ? " (the last at " + Significant(made_at_s[needed - 1], 4) + " s)" : ""),
                         reached ? 100 : 0});
    }
  }
  for (const RubricItem& i : s.items) s.total += i.points, s.max_total += i.max;
  return s;
}

}  // namespace mbot::sim
