// The exploration state machine: initializing → exploring → returning home → completed (no
// frontier left on the final map), incomplete (home, but frontiers were left: unreachable or
// unresolved, counted and placed), or failed with a reason. It consumes map and pose updates and produces paths; it
// never drives anything, so it runs the same on a log, in the simulator and on a robot.
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
  // Exploration keeps to mapped space: unknown cells, and cells seen too faintly to count as free for
  // the frontiers, are obstacles for distances and paths.
  ObstacleDistanceOptions distance{/*unknown_is_obstacle=*/true, 0, 0.0, FrontierOptions{}.free_threshold};
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
  // A frontier still there at its target is tried once more from another viewpoint, at least this
  // far from the first (the first may look at it past a wall's end); then it is given up for good.
  double second_view_m = 0.25;
  // At home with frontiers left that can be reached and were given up only for a while (no path
  // then), the explorer forgets those and explores again, at most this many times.
  int home_retries = 2;
};

enum class ExplorationState { kInitializing, kExploring, kReturningHome, kCompleted, kIncomplete, kFailed };
const char* ToString(ExplorationState state);

// A frontier still on the map when exploration ended.
struct FrontierLeft {
  double x = 0, y = 0;       // its centroid [m]
  int cells = 0;             // its size
  bool reachable = false;    // a cell near it can be reached at the planning clearance
  bool blacklisted = false;  // it was given up: unresolved at its target, or no path to it
  bool unresolved = false;   // ... for good: the robot stood at its target and it stayed
};

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
  // The distances the planner keeps from obstacles, as of the last update.
  const ObstacleDistanceGrid& distances() const { return distances_; }
  // Completed or incomplete: the frontiers left on the map when the robot reached home (none when
  // completed).
  const std::vector<FrontierLeft>& left() const { return left_; }
  int replans() const { return replans_; }

 private:
  struct Blacklisted {
    double x, y, until_s;
    int cells;  // the frontier's size when it was given up
  };
  bool IsBlacklisted(const Frontier& f, double t_s, bool* for_good = nullptr) const;
  bool HadFailedView(const Frontier& f) const;  // a viewpoint already failed to resolve it
  void DropBlacklisted(double t_s);             // from frontiers_
  bool PathIsSafe(const motion::Pose2D& pose) const;
  bool SelectFrontier(const mapping::OccupancyGrid& map, const motion::Pose2D& pose, double t_s, ExplorationUpdate* u);
  void Fail(const std::string& reason, ExplorationUpdate* u);
  std::vector<FrontierLeft> FrontiersLeft(const mapping::OccupancyGrid& map, const motion::Pose2D& pose, double t_s);

  ExplorationOptions options_;
  ObstacleDistanceGrid distances_;  // kept up to date incrementally as the map grows
  AStarPlanner planner_;
  ExplorationState state_ = ExplorationState::kInitializing;
  motion::Pose2D home_;
  std::vector<motion::Pose2D> path_;
  std::optional<motion::Pose2D> target_frontier_;  // centroid of the frontier being explored
  int target_size_ = 0;                            // its size in cells when it was chosen
  double reached_at_s_ = -1;                       // when the robot reached the target of the frontier being explored
  std::vector<Blacklisted> blacklist_;
  motion::Pose2D target_point_;  // the viewpoint the robot was sent to
  AvoidViews failed_views_;      // viewpoints from which a frontier did not resolve
  std::vector<Frontier> frontiers_;
  std::vector<FrontierLeft> left_;
  std::string failure_reason_;
  int replans_ = 0;
  int home_retries_left_ = 0;
};

}  // namespace mbot::planning
