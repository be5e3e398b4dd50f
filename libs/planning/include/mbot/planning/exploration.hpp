// The exploration state machine: initializing → exploring → returning home → completed, or failed
// with a reason. It consumes map and pose updates and produces paths; it never drives anything,
// so it runs the same on a log, in the simulator and on a robot.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "mbot/mapping/occupancy_grid.hpp"
#include "mbot/motion/pose2d.hpp"
#include "mbot/planning/astar.hpp"
#include "mbot/planning/frontiers.hpp"
#include "mbot/planning/obstacle_distance_grid.hpp"

namespace mbot::planning {

struct ExplorationOptions {
  AStarOptions astar;
  // Exploration keeps to mapped space: unknown cells count as obstacles for distances and paths.
  ObstacleDistanceOptions distance{/*unknown_is_obstacle=*/true};
  FrontierOptions frontier;
  double home_tolerance_m = 0.03;      // completed when the robot is this close to home
  std::optional<motion::Pose2D> home;  // where to return; default: the pose exploration starts at
  double target_reached_m = 0.10;      // a frontier target counts as reached this close
  // The map reaches the explorer some scans after the robot: a frontier counts as unresolved only
  // when it is still there this long after its target was reached.
  double resolve_wait_s = 1.0;
  double blacklist_s = 30.0;         // how long an unreachable frontier is ignored (one still there
                                     // resolve_wait_s after its target was reached is ignored for good)
  double blacklist_radius_m = 0.30;  // frontiers whose centroid lies this close to a blacklisted one
  double frontier_match_m = 0.50;    // the target frontier still exists if a frontier centroid is this close
};

enum class ExplorationState { kInitializing, kExploring, kReturningHome, kCompleted, kFailed };
const char* ToString(ExplorationState state);

struct ExplorationUpdate {
  ExplorationState state = ExplorationState::kInitializing;
  bool new_path = false;             // `path` replaces the previous one
  std::vector<motion::Pose2D> path;  // the path to follow now (empty: stop)
  std::string reason;                // why the state or path changed (for logs and status)
};

class Explorer {
 public:
  explicit Explorer(const ExplorationOptions& options = {});

  // One step: the latest map and robot pose at time t_s. The first call fixes home.
  ExplorationUpdate Update(const mapping::OccupancyGrid& map, const motion::Pose2D& pose, double t_s);

  ExplorationState state() const { return state_; }
  const std::string& failure_reason() const { return failure_reason_; }
  const motion::Pose2D& home() const { return home_; }
  const std::vector<motion::Pose2D>& path() const { return path_; }
  const std::vector<Frontier>& frontiers() const { return frontiers_; }
  int replans() const { return replans_; }

 private:
  struct Blacklisted {
    double x, y, until_s;
  };
  bool IsBlacklisted(const Frontier& f, double t_s) const;
  bool PathIsSafe(const motion::Pose2D& pose) const;
  bool SelectFrontier(const mapping::OccupancyGrid& map, const motion::Pose2D& pose, double t_s, ExplorationUpdate* u);
  void Fail(const std::string& reason, ExplorationUpdate* u);

  ExplorationOptions options_;
  AStarPlanner planner_;
  ExplorationState state_ = ExplorationState::kInitializing;
  motion::Pose2D home_;
  std::vector<motion::Pose2D> path_;
  std::optional<motion::Pose2D> target_frontier_;  // centroid of the frontier being explored
  int target_size_ = 0;                            // its size in cells when it was chosen
  double reached_at_s_ = -1;                       // when the robot reached the target of the frontier being explored
  std::vector<Blacklisted> blacklist_;
  std::vector<Frontier> frontiers_;
  std::string failure_reason_;
  int replans_ = 0;
};

}  // namespace mbot::planning
