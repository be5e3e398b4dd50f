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
                      {"follow", TaskKind::kFollow},
                      {"heavy_lift", TaskKind::kHeavyLift}},
                     "follow a circuit of waypoints, explore the unknown and return home, make the Warehouse's "
                     "deliveries in the known map, drive the paths a GUI sends, or stack crates with the forklift "
                     "(Heavy Lift)");
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
  o.bump_ahead_m = s.GetDouble("bump_ahead_m", o.bump_ahead_m,
                               "a stall while driving marks an obstacle this far ahead of the robot's centre on the "
                               "map it plans on (0: off) [m]",
                               0.0, 1.0);
  o.bump_keep_s = s.GetDouble("bump_keep_s", o.bump_keep_s, "... kept this long [s]", 0.0, 1e6);
  o.dwell_s = s.GetDouble("dwell_s", o.dwell_s,
                          "warehouse: how long to stand at a target or drop-off [s] (the rules ask " +
                              std::to_string(static_cast<int>(warehouse::kDwellS)) + " s)",
                          0.0, 600.0);
  o.heavy_lift = ParseHeavyLiftOptions(s, o.task == TaskKind::kHeavyLift && !describing);
  return o;
}

HeavyLiftOptions ParseHeavyLiftOptions(config::Section& s, bool required) {
  HeavyLiftOptions h;
  const auto doc = [](const std::string& text) { return "heavy_lift: " + text; };
  for (const std::string& item :
       s.GetList("stack", {},
                 doc("the day's crates, in order: <crate id>:<id of the crate to stack it on>, comma separated"))) {
    const size_t colon = item.find(':');
    int a = -1, b = -1;
    try {
      size_t used_a = 0, used_b = 0;
      if (colon != std::string::npos) {
        a = std::stoi(item.substr(0, colon), &used_a);
        b = std::stoi(item.substr(colon + 1), &used_b);
      }
      if (colon == std::string::npos || used_a != colon || used_b != item.size() - colon - 1) a = -1;
    } catch (const std::exception&) {
      a = -1;
    }
    if (a < 0 || b < 0 || a == b) s.Fail("stack", "'" + item + "' is not <crate id>:<other crate id>");
    h.stack.emplace_back(a, b);
  }
  if (required && h.stack.empty()) s.Fail("stack", "task = heavy_lift needs at least one <crate>:<crate> pair");
  h.crate_side_m = s.GetDouble("crate_side_m", h.crate_side_m, doc("the crates' side [m]"), 0.01, 2.0);
  h.crate_height_m = s.GetDouble("crate_height_m", h.crate_height_m, doc("the crates' height [m]"), 0.01, 2.0);
  h.fork_tip_x_m =
      s.GetDouble("fork_tip_x_m", h.fork_tip_x_m, doc("the tines' tips ahead of the robot's centre [m]"), 0.01, 2.0);
  h.insert_depth_m = s.GetDouble("insert_depth_m", h.insert_depth_m,
                                 doc("how far past a crate's face the tips go before lifting [m]"), 0.0, 1.0);
  h.standoff_m = s.GetDouble("standoff_m", h.standoff_m,
                             doc("the tips stop this far before a face to look and line up [m]"), 0.02, 2.0);
  h.carry_height_m = s.GetDouble("carry_height_m", h.carry_height_m,
                                 doc("the tines' height carrying a crate from place to place (low: it hides less of "
                                     "the camera's view) [m]"),
                                 0.0, 2.0);
  h.stack_height_m = s.GetDouble("stack_height_m", h.stack_height_m,
                                 doc("the tines' height setting a crate on another (its underside above the other's "
                                     "top) [m]"),
                                 0.0, 2.0);
  h.place_standoff_m = s.GetDouble(
      "place_standoff_m", h.place_standoff_m,
      doc("before stacking, the carried crate's centre stops this far short of the other's [m]"), 0.02, 2.0);
  h.retreat_m = s.GetDouble("retreat_m", h.retreat_m, doc("backing off after a lift or a stack [m]"), 0.05, 5.0);
  h.approach_speed_m_s = s.GetDouble("approach_speed_m_s", h.approach_speed_m_s,
                                     doc("speed inserting, placing and backing off [m/s]"), 0.005, 0.5);
  h.align_lateral_m =
      s.GetDouble("align_lateral_m", h.align_lateral_m,
                  doc("at a stand-off, off the approach line by more than this: line up again [m]"), 0.001, 0.5);
  h.align_heading_deg =
      s.GetDouble("align_heading_deg", h.align_heading_deg,
                  doc("at a stand-off, turned from the line by more than this: line up again [deg]"), 0.1, 45.0);
  h.look_s = s.GetDouble("look_s", h.look_s, doc("at a stand-off, look this long before going in [s]"), 0.0, 60.0);
  h.search_turn_rad_s = s.GetDouble("search_turn_rad_s", h.search_turn_rad_s,
                                    doc("turn rate on the spot while looking for a crate [rad/s]"), 0.05, 3.0);
  h.max_tag_range_m = s.GetDouble("max_tag_range_m", h.max_tag_range_m,
                                  doc("tag sightings farther than this are left out [m]"), 0.1, 20.0);
  h.no_path_wait_s =
      s.GetDouble("no_path_wait_s", h.no_path_wait_s,
                  doc("no path to a crate's stand-off (the map still too young): try again this long [s]"), 0.0, 600.0);
  h.max_attempts = static_cast<int>(
      s.GetInt("max_attempts", h.max_attempts, doc("tries to engage a crate before giving it up"), 1, 100));
  return h;
}

}  // namespace mbot::mission
