// The Warehouse event's rules (Winter 2024), shared by the robot's side (the warehouse task: what
// to do) and the judge's (libs/sim's referee: what counts), so the two agree on the stops. From the
// day's targets and drop-offs and a seed they give the ordered stops: each delivery is a target
// (the crate is lifted: the robot dwells there) and then a drop-off (dwell again). Levels: 1
// delivery in the first 3 minutes, 2 more by minute 6, 4 more by minute 12. The forklift is not
// simulated, so lifting is standing at the pose, within the tolerances, for kDwellS.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mbot/motion/pose2d.hpp"

namespace mbot::mission::warehouse {

struct Level {
  int deliveries;     // deliveries this level adds
  double deadline_s;  // by this time after the start of the event
};
const std::vector<Level>& Levels();
constexpr double kToleranceM = 0.08;    // position tolerance at a stop [m]
constexpr double kToleranceDeg = 15.0;  // heading tolerance at a stop [deg]
constexpr double kDwellS = 2.0;         // lifting or setting down: standing at the stop this long [s]

struct Stop {
  motion::Pose2D pose;  // map frame (the known map's frame)
  bool pickup = true;   // at a target (lift) or at a drop-off (set down)
  int delivery = 0;     // 0-based
  int index = 0;        // which target / drop-off of the day's lists, 0-based
  std::string Name() const;
};

int TotalDeliveries();

// Deliveries go to distinct targets in a seeded random order, each on to the drop-offs in turn.
// Throws std::invalid_argument when there are fewer targets than deliveries or no drop-off.
std::vector<Stop> Stops(const std::vector<motion::Pose2D>& targets, const std::vector<motion::Pose2D>& dropoffs,
                        uint64_t seed);

// Whether `pose` counts as standing at `stop` (within kToleranceM and kToleranceDeg).
bool AtStop(const motion::Pose2D& pose, const motion::Pose2D& stop);

}  // namespace mbot::mission::warehouse
