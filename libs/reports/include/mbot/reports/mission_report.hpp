// mission.json: what the mission did (mission::MissionReport) — its final state, commands, paths,
// recoveries, and per task the stops, the crates, the frontiers left.
#pragma once

#include "mbot/mission/mission.hpp"
#include "mbot/reports/json.hpp"

namespace mbot::reports {

// `frontiers`: list the frontiers left (exploration, or a task that explored first).
Json MissionJson(const mission::MissionReport& r, bool interrupted, bool frontiers);

}  // namespace mbot::reports
