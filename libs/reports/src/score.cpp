#include "mbot/reports/score.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "mbot/common/strings.hpp"

namespace mbot::reports {
namespace {

Json ErrorJson(const sim::PoseError& e) {
  return {{"x_m", Number(e.x_m)}, {"y_m", Number(e.y_m)}, {"theta_deg", Number(e.theta_deg)}};
}

Json Optional(const std::optional<double>& v) { return v ? Number(*v) : Json(nullptr); }

}  // namespace

std::string ScoreResult(const sim::Score& s) { return s.timed_out ? "time limit" : msgs::ToString(s.state); }

Json ScoreReport(const sim::Score& s, const ScoreContext& c) {
  const double rtf = c.wall_s > 0 ? s.sim_s / c.wall_s : 0.0;
  Json j;
  j["event"] = sim::ToString(s.event);
  j["world"] = c.world;
  j["arena"] = c.arena;
  j["seed"] = c.seed;
  j["state"] = msgs::ToString(s.state);
  j["detail"] = s.detail;
  j["completed"] = s.completed;
  j["incomplete"] = s.incomplete;
  j["timed_out"] = s.timed_out;
  j["interrupted"] = c.interrupted;
  j["time_s"] = Number(s.time_s);
  j["sim_seconds"] = Number(s.sim_s);
  j["wall_seconds"] = Number(c.wall_s);
  j["real_time_factor"] = Number(rtf);
  j["collisions"] = s.collisions;
  Json hits = Json::array();
  for (const sim::CollisionRecord& r : s.collision_events) {
    Json h = {{"t_s", Number(r.t_s)}, {"pose", PoseJson(r.pose)}};
    if (r.estimate) {
      h["estimate"] = PoseJson(*r.estimate);
      h["estimate_error_m"] = Number(r.estimate_error_m);  // null without the truth at its time
      h["estimate_age_s"] = Number(r.estimate_age_s);
    }
    hits.push_back(std::move(h));
  }
  j["collision_events"] = std::move(hits);
  j["start"] = PoseJson(s.start);
  j["final"] = PoseJson(s.final_pose);
  if (s.final_error) j["final_error"] = ErrorJson(*s.final_error);
  if (s.slam_final_error) j["slam_final_error"] = ErrorJson(*s.slam_final_error);
  if (s.map) {
    j["map"] = {{"coverage", Number(s.map->coverage)},
                {"coverage_one_cell", Number(s.map->coverage_one_cell)},
                {"wall_precision", Number(s.map->precision)},
                {"reachable_cells", s.map->reachable_cells},
                {"occupied_cells", s.map->occupied_cells}};
  }
  if (s.event == sim::CompetitionEvent::kWarehouse) {
    j["localized_at_s"] = Optional(s.localized_at_s);
    j["levels_reached"] = s.levels_reached;
    Json stops = Json::array();
    for (const sim::StopResult& r : s.stops) {
      stops.push_back({{"stop", r.stop.Name()},
                       {"pose", PoseJson(r.stop.pose)},
                       {"done_at_s", Optional(r.done_at_s)},
                       {"missed", r.missed}});
    }
    j["stops"] = std::move(stops);
  }
  if (s.event == sim::CompetitionEvent::kHeavyLift) {
    Json crates = Json::array();
    for (const sim::CrateResult& r : s.crates) {
      crates.push_back({{"id", r.id},
                        {"on", r.on_id},
                        {"lifted", r.lifted},
                        {"stacked", r.stacked},
                        {"fell", r.fell},
                        {"final", PoseJson(r.final_pose)},
                        {"final_z_m", Number(r.final_z_m)}});
    }
    j["crates"] = std::move(crates);
  }
  Json points;
  for (const sim::RubricItem& i : s.items) points[i.name] = i.points;
  points["total"] = s.total;
  points["max"] = s.max_total;
  j["points"] = std::move(points);
  return j;
}

std::string RubricText(const sim::Score& s, const ScoreContext& c) {
  const double rtf = c.wall_s > 0 ? s.sim_s / c.wall_s : 0.0;
  std::ostringstream t;
  t << "\n"
    << sim::Title(s.event) << " - arena " << c.arena << ", seed " << c.seed << ": " << ScoreResult(s) << " after "
    << Significant(s.time_s, 4) << " s (" << Significant(rtf, 3) << "x real time), " << s.collisions << " collisions\n";
  for (const sim::RubricItem& i : s.items) {
    t << "  " << std::left << std::setw(20) << i.name << std::setw(68) << i.detail << std::right << std::setw(4)
      << i.points << " / " << i.max << "\n";
  }
  t << "  " << std::left << std::setw(88) << "total" << std::right << std::setw(4) << s.total << " / " << s.max_total
    << "\n";
  for (const sim::CollisionRecord& r : s.collision_events) {
    t << "  collision at " << Significant(r.t_s, 4) << " s, true pose (" << Significant(r.pose.x, 3) << ", "
      << Significant(r.pose.y, 3) << ") m";
    if (r.estimate)
      t << ", SLAM's estimate " << Significant(r.estimate_age_s, 2) << " s before it "
        << Significant(r.estimate_error_m, 2) << " m off the truth then";
    t << "\n";
  }
  return t.str();
}

}  // namespace mbot::reports
