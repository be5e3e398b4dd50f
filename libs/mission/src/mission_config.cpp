#include "mbot/mission/mission_config.hpp"

#include "mbot/common/config.hpp"
#include "mbot/mission/warehouse_rules.hpp"
#include "mbot/motion/motion_config.hpp"
#include "mbot/planning/planning_config.hpp"

namespace mbot::mission {
namespace {

std::vector<motion::Pose2D> ToPoses(const std::vector<config::PoseValue>& v) {
  std::vector<motion::Pose2D> poses;
  for (const config::PoseValue& p : v) poses.push_back({p.x_m, p.y_m, p.theta_rad});
  return poses;
}

}  // namespace

MissionOptions ParseMissionOptions(config::Section& s) {
  MissionOptions o;
  o.task = s.GetEnum("task", o.task,
                     {{"waypoints", TaskKind::kWaypoints},
                      {"explore", TaskKind::kExplore},
                      {"warehouse", TaskKind::kWarehouse},
                      {"follow", TaskKind::kFollow}},
                     "follow a circuit of waypoints, explore the unknown and return home, make the Warehouse's "
                     "deliveries in the known map, or drive the paths a GUI sends");
  // Every task's inputs are read whatever the task (a config that names the Warehouse's may run
  // another task); only the chosen task's are required.
  const bool describing = s.describing();
  o.waypoints =
      ToPoses(s.GetPoses("waypoints", {}, "waypoints: the circuit in the map frame (SLAM starts at the origin)"));
  if (o.task == TaskKind::kWaypoints && o.waypoints.empty() && !describing) {
    s.Fail("waypoints", "task = waypoints needs at least one waypoint");
  }
  {
    o.targets =
        ToPoses(s.GetPoses("targets", {}, "warehouse: the day's targets (crates to lift) in the known map's frame"));
    o.dropoffs = ToPoses(s.GetPoses("dropoffs", {}, "warehouse: the day's drop-offs in the known map's frame"));
    const size_t needed = static_cast<size_t>(warehouse::TotalDeliveries());
    const bool warehouse_task = o.task == TaskKind::kWarehouse && !describing;
    if (warehouse_task && o.targets.size() < needed) {
      s.Fail("targets", "the Warehouse needs " + std::to_string(needed) + " targets, " +
                            std::to_string(o.targets.size()) + " given");
    }
    if (warehouse_task && o.dropoffs.empty()) s.Fail("dropoffs", "the Warehouse needs at least one drop-off");
    o.deliveries =
        static_cast<int>(s.GetInt("deliveries", o.deliveries,
                                  "warehouse: make only the first this many deliveries of the seed's order, for a "
                                  "short run (0: all the rules ask)",
                                  0, warehouse::TotalDeliveries()));
  }
  o.repeat = static_cast<int>(s.GetInt("repeat", o.repeat,
                                       "start the task again this many times once it completes (a soak run; the "
                                       "warehouse takes the next seed's order each round)",
                                       0, 1000000));
  o.explore_first = s.GetBool("explore_first", o.explore_first,
                              "explore and return home first, then run the task on the map made (full SLAM)");
  o.controller = motion::ParseMotionControllerOptions(s);
  o.exploration = planning::ParseExplorationOptions(s);
  o.explore_period_s =
      s.GetDouble("explore_period_s", o.explore_period_s, "explorer updates at most this often [s]", 0.0, 60.0);
  o.start_delay_s =
      s.GetDouble("start_delay_s", o.start_delay_s, "stand still this long after the first SLAM pose [s]", 0.0, 60.0);
  o.max_pose_age_s =
      s.GetDouble("max_pose_age_s", o.max_pose_age_s, "stop when the SLAM pose is older than this [s]", 0.01, 60.0);
  o.control_lag_s =
      s.GetDouble("control_lag_s", o.control_lag_s,
                  "the controller sees the pose predicted this far ahead (the wheels' response lag) [s]", 0.0, 2.0);
  o.max_corrections = static_cast<int>(
      s.GetInt("max_corrections", o.max_corrections,
               "times the final pose is driven to again when the robot stopped outside the tolerances", 0, 100));
  o.stuck_s = s.GetDouble("stuck_s", o.stuck_s, "commanded to move but stalled this long: back off [s]", 0.1, 60.0);
  o.max_stalls = static_cast<int>(
      s.GetInt("max_stalls", o.max_stalls, "stalls on the way to one goal before the mission fails", 0, 100000));
  o.backoff_s = s.GetDouble("backoff_s", o.backoff_s, "how long to reverse at 0.1 m/s when stalled [s]", 0.0, 10.0);
  o.dwell_s = s.GetDouble("dwell_s", o.dwell_s,
                          "warehouse: how long to stand at a target or drop-off [s] (the rules ask " +
                              std::to_string(static_cast<int>(warehouse::kDwellS)) + " s)",
                          0.0, 600.0);
  return o;
}

}  // namespace mbot::mission
