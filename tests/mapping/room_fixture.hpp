// A tiny world for the mapping tests: a 4 m square room at 5 cm and the scan a lidar sees in it.
#pragma once

#include <cmath>
#include <vector>

#include "mbot/mapping/moving_scan.hpp"
#include "mbot/mapping/occupancy_grid.hpp"
#include "mbot/motion/pose2d.hpp"

namespace mbot::mapping {

// The scan a lidar of `beams` evenly spaced beams at `truth` sees in `map` (ray-marched), in the
// robot's frame.
inline std::vector<ScanRay> MarchScan(const OccupancyGrid& map, const motion::Pose2D& truth, int beams = 180) {
  std::vector<ScanRay> rays;
  for (int k = 0; k < beams; ++k) {
    const double a = truth.theta + k * 2 * M_PI / beams;
    double r = 0;
    int cx, cy;
    do {
      r += 0.005;
      map.WorldToCell(truth.x + r * std::cos(a), truth.y + r * std::sin(a), &cx, &cy);
    } while (map.at(cx, cy) <= 0);
    const double la = a - truth.theta;
    rays.push_back(ScanRay{0, 0, float(r * std::cos(la)), float(r * std::sin(la)), true});
  }
  return rays;
}

// A 4 m square room at 5 cm with the robot at (1.0, 0.5, 0.3) and a full-turn scan from there.
struct Room {
  OccupancyGrid map{80, 80, 0.05, -2.0, -2.0, -100};
  std::vector<ScanRay> rays;
  motion::Pose2D truth{1.0, 0.5, 0.3};
  Room() {
    for (int i = 0; i < 80; ++i) map.at(i, 0) = map.at(i, 79) = map.at(0, i) = map.at(79, i) = 100;
    rays = MarchScan(map, truth);
  }
};

}  // namespace mbot::mapping
