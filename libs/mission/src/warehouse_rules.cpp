#include "mbot/mission/warehouse_rules.hpp"

#include <cmath>
#include <random>
#include <stdexcept>

namespace mbot::mission::warehouse {

const std::vector<Level>& Levels() {
  static const std::vector<Level> levels{{1, 180.0}, {2, 360.0}, {4, 720.0}};
  return levels;
}

std::string Stop::Name() const {
  return std::string(pickup ? "target " : "drop-off ") + std::to_string(index + 1) + " (delivery " +
         std::to_string(delivery + 1) + ")";
}

int TotalDeliveries() {
  int n = 0;
  for (const Level& l : Levels()) n += l.deliveries;
  return n;
}

std::vector<Stop> Stops(const std::vector<motion::Pose2D>& targets, const std::vector<motion::Pose2D>& dropoffs,
                        uint64_t seed) {
  const int n = TotalDeliveries();
  if (static_cast<int>(targets.size()) < n || dropoffs.empty()) {
    throw std::invalid_argument("the Warehouse needs " + std::to_string(n) +
                                " targets and at least one drop-off (has " + std::to_string(targets.size()) + " and " +
                                std::to_string(dropoffs.size()) + ")");
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

bool AtStop(const motion::Pose2D& p, const motion::Pose2D& goal) {
  return std::hypot(p.x - goal.x, p.y - goal.y) <= kToleranceM &&
         std::abs(motion::WrapAngle(p.theta - goal.theta)) * 180.0 / M_PI <= kToleranceDeg;
}

}  // namespace mbot::mission::warehouse
