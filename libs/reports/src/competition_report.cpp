#include "mbot/reports/competition_report.hpp"

#include <iomanip>
#include <sstream>

#include "mbot/common/strings.hpp"

namespace mbot::reports {

CompetitionTotals Totals(const std::vector<CompetitionRow>& rows) {
  CompetitionTotals t;
  for (const CompetitionRow& r : rows) {
    if (!r.scored) {
      t.complete = false;
      continue;
    }
    t.points += r.scored->points, t.max_points += r.scored->max_points;
  }
  return t;
}

std::string CompetitionTable(const std::vector<CompetitionRow>& rows, const std::vector<std::string>& not_run) {
  std::ostringstream t;
  t << "\nCompetition on the simulator (Winter 2024 rules)\n"
    << std::left << std::setw(15) << "event" << std::setw(22) << "arena" << std::setw(6) << "seed" << std::setw(12)
    << "result" << std::right << std::setw(8) << "time s" << std::setw(11) << "points" << std::setw(6) << "hits"
    << std::setw(7) << "RTF"
    << "\n";
  for (const CompetitionRow& r : rows) {
    if (!r.scored) {
      t << std::left << std::setw(15) << r.section << r.result << "\n";
      continue;
    }
    const msgs::EventResult& e = *r.scored;
    t << std::left << std::setw(15) << e.event << std::setw(22) << e.arena.substr(0, 21) << std::setw(6) << e.seed
      << std::setw(12) << r.result.substr(0, 11) << std::right << std::setw(8) << Significant(e.time_s, 4)
      << std::setw(11) << (std::to_string(e.points) + " / " + std::to_string(e.max_points)) << std::setw(6)
      << e.collisions << std::setw(6) << Significant(e.real_time_factor, 3) << "x\n";
  }
  for (const std::string& n : not_run) {
    const auto colon = n.find(':');
    t << std::left << std::setw(15) << n.substr(0, colon) << "not run"
      << (colon == std::string::npos ? "" : ":" + n.substr(colon + 1)) << "\n";
  }
  const CompetitionTotals totals = Totals(rows);
  t << std::left << std::setw(63) << "total" << std::right << std::setw(11)
    << (std::to_string(totals.points) + " / " + std::to_string(totals.max_points))
    << (totals.complete ? "" : "  (incomplete: an event above has no score)") << "\n";
  return t.str();
}

Json CompetitionJson(const std::vector<CompetitionRow>& rows, const std::vector<std::string>& not_run) {
  Json events = Json::array();
  for (const CompetitionRow& r : rows) {
    const std::optional<msgs::EventResult>& e = r.scored;
    Json row;
    row["section"] = r.section;
    row["event"] = e ? e->event : "";
    row["arena"] = e ? e->arena : "";
    row["seed"] = e ? Json(e->seed) : Json(nullptr);
    row["result"] = r.result;
    row["time_s"] = e ? Number(e->time_s, 4) : Json(nullptr);
    row["points"] = e ? Json(e->points) : Json(nullptr);
    row["max_points"] = e ? Json(e->max_points) : Json(nullptr);
    row["collisions"] = e ? Json(e->collisions) : Json(nullptr);
    row["real_time_factor"] = e ? Number(e->real_time_factor, 3) : Json(nullptr);
    row["outputs"] = r.outputs;
    events.push_back(std::move(row));
  }
  const CompetitionTotals totals = Totals(rows);
  Json j;
  j["events"] = std::move(events);
  j["not_run"] = not_run;
  j["points"] = totals.points;
  j["max_points"] = totals.max_points;
  j["complete"] = totals.complete;
  return j;
}

}  // namespace mbot::reports
