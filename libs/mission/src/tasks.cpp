#include "tasks.hpp"

#include <stdexcept>

#include "mbot/mission/warehouse_rules.hpp"
#include "mbot/planning/astar.hpp"

namespace mbot::mission {
namespace {

using motion::Pose2D;

// Drive the circuit once, ending at its last waypoint.
class WaypointTask : public Task {
 public:
  explicit WaypointTask(std::vector<Pose2D> waypoints) : waypoints_(std::move(waypoints)) {
    if (waypoints_.empty()) throw std::invalid_argument("task waypoints: no waypoints given");
  }
  bool Step(Mission& m, const Pose2D&) override {
    if (!started_) {
      started_ = true;
      m.SetGoal(waypoints_.back());
      m.SetPath(waypoints_);
      m.SetState(MissionState::kDriving, "circuit of " + std::to_string(waypoints_.size()) + " waypoints");
    }
    return true;
  }
  void Arrived(Mission& m, const std::string& how) override {
    m.EndFinalLeg();
    m.SetState(MissionState::kCompleted, "circuit driven (" + how + ")");
  }

 private:
  std::vector<Pose2D> waypoints_;
  bool started_ = false;
};

// Frontier exploration, then home (in the heading the robot started with).
class ExploreTask : public Task {
 public:
  ExploreTask(const planning::ExplorationOptions& o, double period_s) : explorer_(o), period_s_(period_s) {}
  bool Step(Mission& m, const Pose2D& pose) override {
    const int64_t t_us = m.now_us();
    if (explored_ || !m.map() || (last_explore_us_ >= 0 && (t_us - last_explore_us_) * 1e-6 < period_s_)) return true;
    last_explore_us_ = t_us;
    const planning::ExplorationUpdate u = explorer_.Update(*m.map(), pose, t_us * 1e-6);
    if (m.watched()) m.ShowExploration(Seen(*m.map()));
    if (u.state == planning::ExplorationState::kFailed) {
      m.SetState(MissionState::kFailed, explorer_.failure_reason());
      m.Hold();
      return false;
    }
    const bool done =
        u.state == planning::ExplorationState::kCompleted || u.state == planning::ExplorationState::kIncomplete;
    if (u.new_path || done) {
      // Home is a pose: the way back ends in the heading the robot started with.
      std::vector<Pose2D> path = u.path;
      if (done) path = {explorer_.home()};
      if (u.state != planning::ExplorationState::kExploring && !path.empty())
        path.back().theta = explorer_.home().theta;
      m.SetPath(path);
    }
    if (done) {
      explored_ = true;  // at home: the controller settles the final pose, then the mission ends
      end_ = u.reason;
      m.SetGoal(explorer_.home());
      m.SetState(MissionState::kReturningHome, "aligning at home");
    } else {
      m.SetState(ToMissionState(u.state), u.reason);
    }
    return true;
  }
  void Arrived(Mission& m, const std::string& how) override {
    m.EndFinalLeg();
    if (explorer_.state() == planning::ExplorationState::kIncomplete) {
      m.SetState(MissionState::kIncomplete, "home, exploration " + end_ + " (" + how + ")");
    } else {
      m.SetState(MissionState::kCompleted, "explored and home (" + how + ")");
    }
  }
  void Stalled(Mission&) override { last_explore_us_ = -1; }  // replan as soon as the back-off ends
  void AddToReport(MissionReport* r) const override { r->frontiers_left = explorer_.left(); }

 private:
  // The explorer's frontiers and distances as plain data (a copy per step: explore_period_s, 4 Hz
  // by default; 160 kB for a 10 m square map at 5 cm).
  ExplorationOut Seen(const mapping::OccupancyGrid& map) const {
    ExplorationOut seen;
    seen.frontiers.cell_size_m = map.resolution();
    for (const planning::Frontier& f : explorer_.frontiers()) {
      msgs::FrontierRegion r{f.centroid_x, f.centroid_y, {}};
      r.cells.reserve(f.cells.size());
      for (int i : f.cells) {
        double x = 0, y = 0;
        map.CellToWorld(i % map.width(), i / map.width(), &x, &y);
        r.cells.push_back({x, y, 0.0});
      }
      seen.frontiers.regions.push_back(std::move(r));
    }
    const planning::ObstacleDistanceGrid& d = explorer_.distances();
    if (d.width() > 0 && d.height() > 0) {
      auto grid = std::make_shared<msgs::DistanceGrid>();
      grid->width = d.width();
      grid->height = d.height();
      grid->resolution_m = d.resolution();
      grid->origin_x = d.origin_x();
      grid->origin_y = d.origin_y();
      grid->distance_m = d.distances();
      seen.distances = std::move(grid);
    }
    return seen;
  }
  static MissionState ToMissionState(planning::ExplorationState s) {
    switch (s) {
      case planning::ExplorationState::kInitializing: return MissionState::kInitializing;
      case planning::ExplorationState::kExploring: return MissionState::kExploring;
      case planning::ExplorationState::kReturningHome: return MissionState::kReturningHome;
      case planning::ExplorationState::kCompleted: return MissionState::kCompleted;
      case planning::ExplorationState::kIncomplete: return MissionState::kIncomplete;
      case planning::ExplorationState::kFailed: return MissionState::kFailed;
    }
    return MissionState::kFailed;
  }
  planning::Explorer explorer_;
  double period_s_;
  int64_t last_explore_us_ = -1;
  bool explored_ = false;  // the explorer is done; the controller finishes at home
  std::string end_;        // how the explorer ended ("completed: …" or "incomplete: …")
};

// The Warehouse: stand still until global localization has settled, then drive to each stop in
// turn (A* on the known map), stand there for dwell_s, and go on.
class WarehouseTask : public Task {
 public:
  WarehouseTask(const MissionOptions& o, uint64_t seed)
      : stops_(warehouse::Stops(o.targets, o.dropoffs, seed)),
        planner_(o.exploration.astar),
        distance_(o.exploration.distance),
        dwell_s_(o.dwell_s) {
    if (o.deliveries > 0 && 2 * static_cast<size_t>(o.deliveries) < stops_.size()) stops_.resize(2 * o.deliveries);
  }

  bool Step(Mission& m, const Pose2D& pose) override {
    // Localized in the known map, or mapping (full SLAM, after exploring: its pose is tracked).
    const std::optional<mapping::SlamState> slam = m.slam_state();
    if (slam != mapping::SlamState::kLocalized && slam != mapping::SlamState::kMapping) {
      m.SetState(MissionState::kLocalizing, "waiting for SLAM to localize (it says " +
                                                std::string(slam ? mapping::ToString(*slam) : "nothing yet") + ")");
      if (m.final_leg()) need_plan_ = true;  // the path was planned from a pose no longer trusted
      m.Hold();
      return false;
    }
    if (!planner_.has_map()) {
      if (!m.map()) {
        m.SetState(MissionState::kLocalizing, "waiting for the known map");
        m.Hold();
        return false;
      }
      planner_.SetMap(planning::ObstacleDistanceGrid(*m.map(), distance_));
    }
    const int64_t t_us = m.now_us();
    if (dwell_until_us_ >= 0) {
      if (t_us < dwell_until_us_) {
        m.Hold();
        return false;
      }
      dwell_until_us_ = -1;
      if (++stop_index_ == stops_.size()) {
        m.SetState(MissionState::kCompleted,
                   "stood at all " + std::to_string(stops_.size()) + " targets and drop-offs by its own estimate");
        m.Hold();
        return false;
      }
      need_plan_ = true;
    }
    if (need_plan_ && !m.backing_off()) {
      const warehouse::Stop& stop = stops_[stop_index_];
      const planning::PlanResult r = planner_.PlanSteppingOut(pose, stop.pose);
      if (r.status != planning::PlanStatus::kFound) {
        m.SetState(MissionState::kFailed, "no path to " + stop.Name() + ": " + planning::ToString(r.status));
        m.Hold();
        return false;
      }
      need_plan_ = false;
      m.SetGoal(stop.pose);
      m.SetPath(r.path);
      m.SetState(MissionState::kDriving, "to " + stop.Name() + " of " + std::to_string(stops_.size() / 2));
    }
    return true;
  }
  void Arrived(Mission& m, const std::string& how) override {
    m.EndFinalLeg();
    const warehouse::Stop& stop = stops_[stop_index_];
    dwell_until_us_ = m.now_us() + static_cast<int64_t>(dwell_s_ * 1e6);
    m.SetState(stop.pickup ? MissionState::kLifting : MissionState::kSettingDown,
               "at " + stop.Name() + " (" + how + ")");
  }
  void Stalled(Mission& m) override {
    if (m.final_leg()) need_plan_ = true;
  }
  void AddToReport(MissionReport* r) const override {
    r->stops = static_cast<int>(stops_.size());
    r->stops_done = static_cast<int>(stop_index_);
  }

 private:
  std::vector<warehouse::Stop> stops_;
  size_t stop_index_ = 0;
  planning::AStarPlanner planner_;
  planning::ObstacleDistanceOptions distance_;
  double dwell_s_;
  bool need_plan_ = true;
  int64_t dwell_until_us_ = -1;
};

// Follow: drive each path a GUI sends (the latest replaces the one being driven); between paths,
// stand still.
class FollowTask : public Task {
 public:
  bool Step(Mission& m, const Pose2D&) override {
    if (!pending_.empty()) {
      m.SetGoal(pending_.back());
      m.SetPath(pending_, /*publish=*/false);
      m.SetState(MissionState::kDriving, "a path of " + std::to_string(pending_.size()) + " poses");
      pending_.clear();
    }
    if (m.final_leg()) return true;
    if (m.status().state != MissionState::kArrived) m.SetState(MissionState::kWaiting, "for a path");
    m.Hold();
    return false;
  }
  void Arrived(Mission& m, const std::string& how) override {
    m.EndFinalLeg();
    m.SetState(MissionState::kArrived, "at the end of the path (" + how + ")");
  }
  void PathReceived(const std::vector<Pose2D>& path) override { pending_ = path; }
  bool Resumes() const override { return !pending_.empty(); }
  bool PublishesPaths() const override { return false; }

 private:
  std::vector<Pose2D> pending_;  // received and not yet taken
};

}  // namespace

std::unique_ptr<Task> MakeTask(const MissionOptions& o, uint64_t seed) {
  switch (o.task) {
    case TaskKind::kWaypoints: return std::make_unique<WaypointTask>(o.waypoints);
    case TaskKind::kExplore: return std::make_unique<ExploreTask>(o.exploration, o.explore_period_s);
    case TaskKind::kWarehouse: return std::make_unique<WarehouseTask>(o, seed);
    case TaskKind::kFollow: return std::make_unique<FollowTask>();
    case TaskKind::kHeavyLift: return MakeHeavyLiftTask(o);
  }
  throw std::invalid_argument("unknown task");
}

}  // namespace mbot::mission
