#include "mbot/reports/mission_report.hpp"

namespace mbot::reports {

Json MissionJson(const mission::MissionReport& r, bool interrupted, bool frontiers) {
  Json j;
  j["task"] = mission::ToString(r.task);
  j["state"] = msgs::ToString(r.status.state);
  j["detail"] = r.status.detail;
  j["interrupted"] = interrupted;
  j["commands"] = r.commands;
  j["paths"] = r.paths;
  j["stale_pose_stops"] = r.stale_pose_stops;
  j["corrections"] = r.corrections;
  j["stall_recoveries"] = r.stall_recoveries;
  j["bumps"] = r.bumps;
  j["odometry_restarts"] = r.odometry_restarts;
  j["odometry_outliers"] = r.odometry_outliers;
  j["odometry_duplicates"] = r.odometry_duplicates;
  j["last_command"] = {{"v_m_s", r.last_command.v_m_s}, {"w_rad_s", r.last_command.w_rad_s}};
  j["rounds"] = r.rounds;
  if (r.task == mission::TaskKind::kWarehouse) {
    j["stops"] = r.stops;
    j["stops_done"] = r.stops_done;
  }
  if (r.task == mission::TaskKind::kHeavyLift) {
    j["crates"] = r.crates;
    j["crates_lifted"] = r.crates_lifted;
    j["crates_set_down"] = r.crates_set_down;
    j["tag_sightings"] = r.tag_sightings;
  }
  if (frontiers) {
    Json left = Json::array();
    for (const planning::FrontierLeft& f : r.frontiers_left) {
      left.push_back({{"x", Number(f.x)},
                      {"y", Number(f.y)},
                      {"cells", f.cells},
                      {"reachable", f.reachable},
                      {"given_up", f.unresolved    ? Json("for good")
                                   : f.blacklisted ? Json("for a while")
                                                   : Json(false)}});
    }
    j["frontiers_left"] = std::move(left);
  }
  return j;
}

}  // namespace mbot::reports
