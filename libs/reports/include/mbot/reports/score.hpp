// score.json and the printed rubric of a competition event on the simulator (sim::Score).
#pragma once

#include <cstdint>
#include <string>

#include "mbot/reports/json.hpp"
#include "mbot/sim/referee.hpp"

namespace mbot::reports {

struct ScoreContext {
  std::string world;  // the world file
  std::string arena;  // its name
  uint64_t seed = 0;
  bool interrupted = false;
  double wall_s = 0;  // the run's wall time (the real-time factor's denominator)
};

// score.json: the score as the rubric counts it.
Json ScoreReport(const sim::Score& s, const ScoreContext& c);
// "time limit" or the mission's final state.
std::string ScoreResult(const sim::Score& s);
// The rubric as printed at the end of an event: a title line, a line per item, the total.
std::string RubricText(const sim::Score& s, const ScoreContext& c);

}  // namespace mbot::reports
