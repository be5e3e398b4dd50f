// The competition's table (printed) and competition.json: one row per event section, scored or not.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "mbot/msgs/stage.hpp"
#include "mbot/reports/json.hpp"

namespace mbot::reports {

struct CompetitionRow {
  std::string section;  // the event's section name
  std::string result;   // the referee's result, or why there is none
  std::string outputs;  // the event's output folder
  std::optional<msgs::EventResult> scored;
};

struct CompetitionTotals {
  int points = 0, max_points = 0;
  bool complete = true;  // every event that should have scored did
};
CompetitionTotals Totals(const std::vector<CompetitionRow>& rows);

// `not_run`: "Event: why" lines for the events the configuration leaves out.
std::string CompetitionTable(const std::vector<CompetitionRow>& rows, const std::vector<std::string>& not_run);
Json CompetitionJson(const std::vector<CompetitionRow>& rows, const std::vector<std::string>& not_run);

}  // namespace mbot::reports
