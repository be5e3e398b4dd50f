// The Warehouse event's rules, shared by the robot's side (the `mission` stage: what to do) and the
// judge's (the `referee` stage: what counts), so the two agree on the stops. From a seed and the
// arena's `target` and `dropoff` poses they give the ordered stops: each delivery is a target (the
// crate is lifted: the robot dwells there) and then a drop-off (dwell again). Levels: 1 delivery in
// the first 3 minutes, 2 more by minute 6, 4 more by minute 12. The forklift is not simulated, so
// lifting is standing at the pose, within the tolerances, for kDwellS.
#pragma once

#include <algorithm>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "mbot/drivers/sim_world.hpp"
#include "mbot/motion/pose2d.hpp"

namespace mbot::app::warehouse {

struct Level {
  int deliveries;     // deliveries this level adds
  double deadline_s;  // by this time after the start of the event
};
inline const std::vector<Level>& Levels() {
  static const std::vector<Level> levels{{1, 180.0}, {2, 360.0}, {4, 720.0}};
  return levels;
}
constexpr double kToleranceM = 0.08;      // position tolerance at a stop [m]
constexpr double kToleranceDeg = 15.0;    // heading tolerance at a stop [deg]
constexpr double kDwellS = 2.0;           // lifting or setting down: standing at the stop this long [s]

struct Stop {
  motion::Pose2D pose;   // world frame (the known map's frame)
  bool pickup = true;    // at a target (lift) or at a drop-off (set down)
  int delivery = 0;      // 0-based
  int arena_index = 0;   // which `target` / `dropoff` of the arena file, 0-based
  std::string Name() const {
    return std::string(pickup ? "target " : "drop-off ") + std::to_string(arena_index + 1) + " (delivery " +
           std::to_string(delivery + 1) + ")";
  }
};

inline int TotalDeliveries() {
  int n = 0;
  for (const Level& l : Levels()) n += l.deliveries;
  return n;
}

// Deliveries go to distinct targets in a seeded random order, each on to the drop-offs in turn.
// Throws when the arena has too few targets or no drop-off.
inline std::vector<Stop> Stops(const drivers::World& world, uint64_t seed) {
  const std::vector<motion::Pose2D> targets = world.PosesLabelled("target");
  const std::vector<motion::Pose2D> dropoffs = world.PosesLabelled("dropoff");
  const int n = TotalDeliveries();
  if (static_cast<int>(targets.size()) < n || dropoffs.empty()) {
    throw std::runtime_error("warehouse: the arena '" + world.name() + "' needs " + std::to_string(n) +
                             " 'pose target' lines and at least one 'pose dropoff' (has " +
                             std::to_string(targets.size()) + " and " + std::to_string(dropoffs.size()) + ")");
  }
  std::vector<int> order(targets.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::mt19937_64 rng(seed ^ 0x77617265686F7573ULL);
  for (size_t i = order.size() - 1; i > 0; --i) {  // Fisher–Yates with our own draws: the same on every library
    std::swap(order[i], order[rng() % (i + 1)]);
  }
  std::vector<Stop> stops;
  for (int d = 0; d < n; ++d) {
    stops.push_back({targets[order[d]], true, d, order[d]});
    const int k = d % static_cast<int>(dropoffs.size());
    stops.push_back({dropoffs[k], false, d, k});
  }
  return stops;
}

}  // namespace mbot::app::warehouse
