// The mission: the robot's autonomy after SLAM. One task — a circuit of waypoints, exploring and
// returning home, the Warehouse's deliveries in a known map, or driving the paths a GUI sends —
// decides where to go (A* paths, frontiers); the mission around it turns the pose into velocity
// commands through the motion controller and owns what every task shares: the pose between SLAM
// updates (the SLAM pose moved on by odometry), stall recovery (back off, replan), and settling at
// a goal (wait until the robot stands still, correct the final pose). It never touches a file, a
// bus or a clock: the caller hands it SLAM's outputs and the odometry with their times, and gets
// back what to command and publish. Frames: every pose is in the map frame (SLAM's), metres and
// radians; times are microseconds on the data's clock.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "mbot/mapping/occupancy_grid.hpp"
#include "mbot/mapping/slam.hpp"
#include "mbot/mission/mission_state.hpp"
#include "mbot/motion/motion_controller.hpp"
#include "mbot/motion/odometry_continuity.hpp"
#include "mbot/motion/pose2d.hpp"
#include "mbot/msgs/events.hpp"
#include "mbot/planning/exploration.hpp"

namespace mbot::mission {

enum class TaskKind { kWaypoints, kExplore, kWarehouse, kFollow, kHeavyLift };
const char* ToString(TaskKind kind);

// A tag the camera saw, in the robot frame at the frame's time: the tag's centre [m] and the
// heading its face looks towards (the face's outward normal, robot frame) [rad].
struct TagSeen {
  int id = 0;
  double x_m = 0, y_m = 0, z_m = 0;
  double facing_rad = 0;
};

// What the forklift reports (MBOT_FORKLIFT_STATUS): the tines' height and target [m], the crate on
// them (-1: none), and whether it is lifted off what it stood on.
struct ForkliftState {
  double height_m = 0, target_m = 0;
  int crate_id = -1;
  bool carrying = false;
};

// Heavy Lift: which crate goes on which, and the forklift's and crates' geometry the moves are
// worked out from (the botlab's: config/heavy_lift.ini documents them).
struct HeavyLiftOptions {
  std::vector<std::pair<int, int>> stack;  // (crate to lift, crate to set it on), in order
  double crate_side_m = 0.10;              // crates are square in plan
  double crate_height_m = 0.08;
  double fork_tip_x_m = 0.18;    // the tines' tips ahead of the robot's centre
  double insert_depth_m = 0.04;  // how far past a crate's face the tips go before lifting
  double standoff_m = 0.12;      // the tips stop this far before a face to look and align
  // The tines' height carrying a crate: low while travelling (the crate hides less of the camera's
  // view), high to set it on another (its underside above the other's top).
  double carry_height_m = 0.05;
  double stack_height_m = 0.13;
  double place_standoff_m = 0.15;    // before stacking, the carried crate stops this far short
  double retreat_m = 0.25;           // backing off after a lift or a stack
  double approach_speed_m_s = 0.05;  // inserting, placing and backing off
  double align_lateral_m = 0.015;    // at the stand-off: off the approach line by at most this …
  double align_heading_deg = 5.0;    // … and turned from it by at most this, else drive to it again
  double look_s = 1.0;               // at a stand-off, look this long (fresh sightings refine the crate)
  double search_turn_rad_s = 0.6;    // turning on the spot to find a crate not yet seen (and once at the start)
  double max_tag_range_m = 1.6;      // farther sightings are left out (their pose is too rough)
  int max_attempts = 3;              // tries to engage a crate before giving it up
  double no_path_wait_s = 10.0;      // no path to a crate (the map still too young): try again this long
};

struct MissionOptions {
  TaskKind task = TaskKind::kWaypoints;
  // waypoints: the circuit, in the map frame (SLAM starts at the origin at the start pose).
  std::vector<motion::Pose2D> waypoints;
  // warehouse: the day's targets and drop-offs in the known map's frame; the order of the
  // deliveries follows from them and the seed (warehouse_rules.hpp).
  std::vector<motion::Pose2D> targets;
  std::vector<motion::Pose2D> dropoffs;
  int deliveries = 0;          // warehouse: make only the first this many of the seed's order (0: all the rules ask)
  int repeat = 0;              // start the task again this many times once it completes (soak runs)
  bool explore_first = false;  // explore (and return home) before the task: its map is the task's
  motion::MotionControllerOptions controller;
  planning::ExplorationOptions exploration;
  double explore_period_s = 0.25;  // explorer updates at most this often [s]
  double start_delay_s = 0.5;      // stand still this long after the first SLAM pose (map the start)
  double max_pose_age_s = 1.0;     // stop when the SLAM pose is older than this [s]
  // The wheels answer a command late (the firmware filters v, ω and the PWM; the motors lag): the
  // controller is given the pose predicted this far ahead at the measured velocity.
  double control_lag_s = 0.2;
  int max_corrections = 5;  // times the final pose is driven to again after stopping outside the tolerances
  double stuck_s = 1.0;     // commanded to move but not moving this long: back off
  double backoff_s = 0.6;   // reversing at 0.1 m/s
  int max_stalls = 10;      // stalls on the way to one goal before the mission gives up
  // A stall while driving marks what the robot ran into on the map it plans on: a small obstacle
  // this far ahead of its centre (behind when reversing), kept for bump_keep_s. Against the free
  // end of a wall, the map's wall is a little short of the real one and the plan would graze the
  // real end again and again (0: off).
  double bump_ahead_m = 0.12;
  double bump_keep_s = 120.0;
  double dwell_s = 2.5;  // warehouse: standing at a stop (lifting, setting down) [s]
  // A person at the viewer: teleop drives only while its commands keep coming (the dead man).
  double teleop_timeout_s = 0.5;
  HeavyLiftOptions heavy_lift;
};

// What the mission asks the caller to do, in order: publish a state, publish a path (the
// controller's plan), or send a velocity command.
struct PathOut {
  std::vector<motion::Pose2D> poses;
};
// Heavy Lift: the height the forklift's tines should go to (MBOT_FORKLIFT_CMD).
struct ForkOut {
  double height_m = 0;
};
// explore: what the explorer sees at each of its steps (for a viewer): its frontiers and the
// distances its planner keeps from obstacles.
struct ExplorationOut {
  msgs::Frontiers frontiers;
  std::shared_ptr<const msgs::DistanceGrid> distances;
};
using MissionOutput = std::variant<MissionStatus, PathOut, motion::VelocityCommand, ForkOut, ExplorationOut>;

// Counters for the mission's report.
struct MissionReport {
  TaskKind task = TaskKind::kWaypoints;
  MissionStatus status;
  long long commands = 0, paths = 0, stale_pose_stops = 0;
  int corrections = 0, stall_recoveries = 0;
  int bumps = 0;              // obstacles marked where the robot stalled
  int odometry_restarts = 0;  // the robot's odometry started again from zero (a firmware restart)
  // Odometry messages the continuity check did not take (a corrupt one; a jump's duplicate), and the
  // last command sent: what a run that ended stopped short of its goal is read by.
  int odometry_outliers = 0, odometry_duplicates = 0;
  motion::VelocityCommand last_command;
  int rounds = 1;  // rounds of the task run (repeat + 1 when all completed)
  // explore: the frontiers left on the map at home (none when completed).
  std::vector<planning::FrontierLeft> frontiers_left;
  // warehouse: stops in all, and done by the mission's own estimate.
  int stops = 0, stops_done = 0;
  // heavy_lift: crates to stack, lifted and set down (on their crates, it meant) by the forklift's
  // report; tag sightings used.
  int crates = 0, crates_lifted = 0, crates_set_down = 0;
  long long tag_sightings = 0;
};

class Task;

class Mission {
 public:
  // `seed` orders the Warehouse's deliveries. Throws std::invalid_argument when the task's inputs
  // are missing (no waypoints, too few targets).
  Mission(const MissionOptions& options, uint64_t seed);
  ~Mission();
  Mission(const Mission&) = delete;
  Mission& operator=(const Mission&) = delete;

  // SLAM's outputs, as they come.
  void OnPoseEstimate(int64_t t_us, const motion::Pose2D& pose);
  void OnMap(std::shared_ptr<const mapping::OccupancyGrid> map);
  void OnSlamState(mapping::SlamState state);
  // follow: a path sent by a GUI (replaces the one being driven).
  void OnPath(const std::vector<motion::Pose2D>& path);
  // A person takes over (the viewer): a goal to drive to (A* on the mission's map, map frame), or a
  // teleop command (clamped to the controller's limits; it stops when the commands stop coming for
  // teleop_timeout_s). Either way the task is paused for the rest of the run: the robot does what
  // the person says, and holds still in between.
  void OnGoal(const motion::Pose2D& goal);
  void OnTeleop(int64_t t_us, double v_m_s, double w_rad_s);
  bool manual() const { return manual_; }
  // Someone watches the run (an output: a viewer): the tasks also say what they see (frontiers,
  // obstacle distances), which costs a copy per exploration step. Off by default.
  void set_watched(bool watched) { watched_ = watched; }
  // heavy_lift: the tags in a camera frame taken at t_us (robot frame), and the forklift's report.
  void OnTags(int64_t t_us, const std::vector<TagSeen>& tags);
  void OnForklift(const ForkliftState& state) { forklift_ = state; }
  // The control step, on every odometry message (the firmware's 50 Hz): what to publish and
  // command now. Every step ends with exactly one velocity command.
  std::vector<MissionOutput> OnOdometry(int64_t t_us, const motion::Pose2D& odometry, int64_t stamp_us = 0);

  const MissionStatus& status() const { return status_; }
  const MissionOptions& options() const { return o_; }
  MissionReport Report() const;

  // --- for the tasks (src/tasks.cpp) ---
  void SetState(MissionState state, const std::string& detail);
  // A new path for the controller; published unless `publish` is false (a path that came in from
  // outside is not sent back).
  void SetPath(const std::vector<motion::Pose2D>& path, bool publish = true);
  // The path ends at `goal`, where the robot must stop within the final tolerances.
  void SetGoal(const motion::Pose2D& goal);
  void Hold();                                                        // command zero velocity this step
  void Drive(double v_m_s, double w_rad_s) { Send(v_m_s, w_rad_s); }  // this step's command, from the task
  void CommandFork(double height_m);                                  // heavy_lift: the tines' target height
  void ShowExploration(ExplorationOut seen);                          // explore: for a viewer
  bool watched() const { return watched_; }
  const std::optional<ForkliftState>& forklift() const { return forklift_; }
  // The pose at t_us (map frame): the SLAM pose moved by odometry; false outside the odometry kept.
  bool PoseAt(int64_t t_us, motion::Pose2D* pose) const;
  bool final_leg() const { return final_leg_; }
  void EndFinalLeg() { final_leg_ = false; }
  bool backing_off() const { return t_us_ < backoff_until_us_; }
  int64_t now_us() const { return t_us_; }
  const std::shared_ptr<const mapping::OccupancyGrid>& map() const { return map_; }
  std::optional<mapping::SlamState> slam_state() const { return slam_state_; }

 private:
  bool PoseNow(motion::Pose2D* pose) const;
  bool FromOdometry(const motion::Pose2D& odometry, motion::Pose2D* pose) const;
  bool Recovering();
  bool Settled(const motion::Pose2D& pose, std::string* how);
  motion::VelocityCommand MeasuredVelocity() const;
  motion::Pose2D Predict(const motion::Pose2D& pose) const;
  void Send(double v, double w);

  MissionOptions o_;
  std::unique_ptr<Task> task_;
  motion::MotionController controller_;
  std::vector<MissionOutput>* out_ = nullptr;  // during OnOdometry
  int64_t t_us_ = 0;                           // the step's time
  motion::TimedPose slam_;
  bool has_slam_ = false;
  int64_t first_slam_us_ = -1, last_control_us_ = -1;
  std::vector<motion::TimedPose> odometry_;  // the last ~5 s, continuous across robot restarts
  motion::OdometryContinuity continuity_;
  std::shared_ptr<const mapping::OccupancyGrid> map_;      // SLAM's map with the bumps marked
  std::shared_ptr<const mapping::OccupancyGrid> raw_map_;  // SLAM's map as it came
  std::vector<motion::TimedPose> bumps_;                   // where stalls met something, and when
  void MarkBumps();
  std::optional<mapping::SlamState> slam_state_;
  std::optional<ForkliftState> forklift_;
  bool final_leg_ = false;  // the path ends at goal_, where the robot must stop within the tolerances
  uint64_t seed_ = 0;
  int rounds_ = 0;  // completed rounds started again (repeat)
  bool exploring_first_ = false;
  motion::Pose2D goal_;
  motion::Pose2D stall_goal_{1e9, 1e9, 0};  // the goal the stall budget is for
  MissionStatus status_;
  long long commands_ = 0, paths_ = 0, stale_stops_ = 0;
  int corrections_ = 0, total_corrections_ = 0, recoveries_ = 0, stalls_this_goal_ = 0, bumps_marked_ = 0;
  motion::VelocityCommand last_command_;
  motion::VelocityCommand last_sent_;  // the last command sent, whatever sent it (the report's)
  bool ManualStep(const motion::Pose2D& pose, double dt);
  bool watched_ = false;
  bool manual_ = false;                        // a person took over
  std::optional<motion::Pose2D> person_goal_;  // to plan for
  motion::VelocityCommand teleop_;             // the last teleop command …
  int64_t teleop_until_us_ = -1;               // … in force until then
  int64_t stuck_since_us_ = -1, backoff_until_us_ = 0;
};

}  // namespace mbot::mission
