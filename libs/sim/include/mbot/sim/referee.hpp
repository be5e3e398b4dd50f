// The competition's judge (Winter 2024 rules): it watches an event on the simulator — the true pose,
// collisions and the world, which only the simulator knows, beside what the stack produced (its SLAM
// poses and map, its states) — and scores it into a Score: the rubric's lines and points, the final
// pose errors, the map's quality, the Warehouse's stops and levels, Heavy Lift's crates. Events:
// speed_run and maze_explorer (SLAM from the start pose: the map frame is the start frame), warehouse
// (localization in the given map: the map frame is the world frame; deliveries judged from the true
// pose against mission/warehouse_rules.hpp), heavy_lift (SLAM from the start pose; +50 per crate
// lifted clear of the floor, +50 per crate standing on its designated crate at the end, judged from
// the simulator's crates). Times are microseconds on the simulation's clock.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mbot/msgs/events.hpp"
#include "mbot/mapping/occupancy_grid.hpp"
#include "mbot/mapping/slam.hpp"
#include "mbot/mission/mission_state.hpp"
#include "mbot/mission/warehouse_rules.hpp"
#include "mbot/motion/pose2d.hpp"
#include "mbot/sim/world.hpp"

namespace mbot::sim {

enum class CompetitionEvent { kSpeedRun, kMazeExplorer, kWarehouse, kHeavyLift };
const char* ToString(CompetitionEvent event);  // "speed_run", "maze_explorer", "warehouse", "heavy_lift"
const char* Title(CompetitionEvent event);     // "Speed Run" …

struct RefereeOptions {
  CompetitionEvent event = CompetitionEvent::kSpeedRun;
  double time_limit_s = 180.0;  // the run ends here if the mission has not
  double finish_delay_s = 0.5;  // keep simulating this long after the mission ends (the robot stops)
  int crates = 0;               // Heavy Lift: judge only the world's first this many stack assignments (0: all)
  // The floor to be mapped is what the robot's body reaches: cells within this radius of a place
  // the robot's centre can get to from the start (keeping this radius from every wall). A gap
  // narrower than the robot (in a map world's walls, say) does not open the space behind it.
  double robot_radius_m = 0.1;
};

// One line of the rubric: what was judged, how it went, the points.
struct RubricItem {
  std::string name, detail;
  int points = 0, max = 100;
};

struct PoseError {
  double x_m = 0, y_m = 0, theta_deg = 0;  // absolute errors per axis
};

struct MapQuality {
  double coverage = 0;           // share of the reachable free space (≥ 1.5 SLAM cells from walls) mapped free
  double coverage_one_cell = 0;  // the same share with one cell kept from the walls
  double precision = 0;          // share of the mapped walls within 1.5 SLAM cells of a true wall
  int reachable_cells = 0, occupied_cells = 0;
  std::vector<motion::Pose2D> unmapped;  // centres of the reachable true cells not mapped free (map frame)
};

// A collision the simulator reported: when (since the start of the event), where the robot truly
// was, and where SLAM placed it then (the map frame taken into the world), to tell a planning
// fault (the estimate right, the path too close) from a localization one.
struct CollisionRecord {
  double t_s = 0;
  motion::Pose2D pose;                     // true, world frame
  std::optional<motion::Pose2D> estimate;  // SLAM's last pose before it, in the world frame
  double estimate_age_s = 0;               // how long before the collision SLAM published it
  // The estimate's distance from the true pose at the estimate's own time (NaN: no truth then).
  double estimate_error_m = NAN;
};

struct StopResult {
  mission::warehouse::Stop stop;
  std::optional<double> done_at_s;  // since the start of the event
  bool missed = false;              // the robot stood at a later stop first
};

// Heavy Lift: one of the day's assignments (crate `id` onto crate `on_id`) and how it ended, from
// the simulator's crates (SIM_CRATES).
struct CrateResult {
  int id = 0, on_id = 0;
  bool lifted = false;   // lifted clear of the floor at some point
  bool stacked = false;  // ends standing on its designated crate
  bool fell = false;     // was set down off-centre and fell
  motion::Pose2D final_pose;
  double final_z_m = 0;
};

struct Score {
  CompetitionEvent event = CompetitionEvent::kSpeedRun;
  mission::MissionState state = mission::MissionState::kInitializing;
  std::string detail;
  bool scored = false;      // false without ground truth (nothing to judge)
  bool completed = false;   // the mission said completed
  bool incomplete = false;  // the mission said incomplete (exploration: home, frontiers left)
  bool timed_out = false;
  double time_s = 0;  // to the mission's end, or the whole run
  double sim_s = 0;   // simulated time seen
  int collisions = 0;
  std::vector<CollisionRecord> collision_events;  // each collision, in order
  motion::Pose2D start, final_pose;               // true, world frame
  motion::Pose2D map_frame;                       // where the map frame lies in the world
  std::optional<PoseError> final_error;           // final pose against the start (not the Warehouse)
  std::optional<PoseError> slam_final_error;      // SLAM's last pose against the truth then
  std::optional<MapQuality> map;                  // not the Warehouse
  std::optional<double> localized_at_s;           // the Warehouse: when global localization settled
  int levels_reached = 0;
  std::vector<StopResult> stops;
  std::vector<CrateResult> crates;  // Heavy Lift
  std::vector<RubricItem> items;
  int total = 0, max_total = 0;
};

// Points for a final pose error, the rubric's tiers (< 3 cm / 3 cm / 15° → 100, 5/5/15 → 75,
// 10/10/30 → 50, 20/20/45 → 25).
int PosePoints(const PoseError& e);
// Lap time tiers: < 15 s → 100, < 20 s → 75, < 30 s → 50.
int LapPoints(double seconds);
// What Quality needs of the world for one start, whatever the map: the true cells the robot can
// reach and their clearance from the walls. The referee works it out once per run.
struct ReachableCells {
  motion::Pose2D start;
  std::vector<double> x, y, clearance;  // world frame [m]
};
ReachableCells FindReachableCells(const World& world, const motion::Pose2D& start, double robot_radius_m);
// The map (in the frame of `reachable.start`) against the world: coverage of the reachable free
// space and precision of the walls.
MapQuality Quality(const World& world, const mapping::OccupancyGrid& map, const ReachableCells& reachable);

class Referee {
 public:
  // Throws std::invalid_argument for a Heavy Lift in a world without stack assignments.
  Referee(const RefereeOptions& options, World world, uint64_t seed);

  // Called first for every event of the stream, with its time.
  void Tick(int64_t t_us);
  void OnTruePose(int64_t t_us, const motion::Pose2D& pose);
  // A collision at the true pose `pose`.
  void OnCollision(int64_t t_us, const motion::Pose2D& pose);
  void OnSlamPose(int64_t t_us, const motion::Pose2D& pose) { slam_.push_back({t_us, pose}); }
  void OnMap(std::shared_ptr<const mapping::OccupancyGrid> map) { map_ = std::move(map); }
  void OnSlamState(int64_t t_us, mapping::SlamState state);
  void OnMissionStatus(int64_t t_us, const mission::MissionStatus& status);
  // Heavy Lift: the simulator's crates as they are now.
  void OnCrates(const msgs::CrateStates& crates) { crates_ = crates; }
  // Why the run should end now — the mission ended finish_delay_s ago, or the time limit — once;
  // nullopt otherwise.
  std::optional<std::string> StopReason(int64_t t_us);

  Score Judge() const;

  const World& world() const { return world_; }
  const std::vector<motion::TimedPose>& truth() const { return truth_; }
  const std::vector<motion::TimedPose>& slam() const { return slam_; }
  const std::shared_ptr<const mapping::OccupancyGrid>& map() const { return map_; }
  const std::vector<mission::warehouse::Stop>& stops() const { return stops_; }

 private:
  void JudgeStop(const motion::TimedPose& truth);

  RefereeOptions o_;
  World world_;
  mutable std::optional<ReachableCells> reachable_;  // for Quality: the same for every Judge of a run
  int64_t t0_us_ = -1, last_us_ = 0, end_us_ = -1, localized_us_ = -1;
  std::vector<motion::TimedPose> truth_, slam_;
  std::shared_ptr<const mapping::OccupancyGrid> map_;
  mission::MissionState state_ = mission::MissionState::kInitializing;
  std::string detail_;
  struct Collision {
    motion::TimedPose truth;                    // when and where it happened
    std::optional<motion::TimedPose> estimate;  // SLAM's last pose before it (map frame)
  };
  std::vector<Collision> collisions_;
  bool stop_sent_ = false, timed_out_ = false;
  // Warehouse.
  std::vector<mission::warehouse::Stop> stops_;
  std::vector<int64_t> stop_done_us_;  // per judged stop, in order: when it was done, -1 missed
  int near_stop_ = -1;                 // the stop the robot stands at, since near_since_us_
  bool left_last_stop_ = true;         // the robot has moved off the last stop done
  int64_t near_since_us_ = -1;
  // Heavy Lift.
  msgs::CrateStates crates_;
};

}  // namespace mbot::sim
