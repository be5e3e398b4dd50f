// Scans made worse on purpose, for robustness tests of SLAM on real logs (issue 31): what a building
// does to a lidar that the recorded data lacks.
//  - Glass: a share of the walls, in 1 m patches fixed in the odometry frame, is glass. A beam that
//    ends on a pane goes through it: half of those give no return (the sensor's maximum, as a SICK
//    reports it), the others a return from 1.5-3 times as far (something behind the pane; the map
//    gains an obstacle where there is none).
//  - People: 0.4 m discs walk straight at 1 m/s, 0.8-4 m from the lidar, 2-6 s each, and are drawn
//    into every beam that meets them before its own return; the map sees moving obstacles, and the
//    walls they hide are missing from those scans.
// Seeded: the same seed and scans give the same perturbed ranges.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "mbot/motion/pose2d.hpp"

namespace mbot::mapping {

struct ScanPerturbationOptions {
  double glass_share = 0.0;  // share of the wall patches that are glass (0: none)
  int people = 0;            // people walking about the robot at any time
  bool any() const { return glass_share > 0 || people > 0; }
};

class ScanPerturbation {
 public:
  ScanPerturbation(const ScanPerturbationOptions& options, uint64_t seed);
  // Perturbs the ranges of one scan taken at `t_us` by a sensor at `sensor` (in the odometry frame);
  // `angles` are the beams' angles in the sensor frame, `max_range_m` the sensor's maximum (0: none
  // known: a beam through glass then gives no return, NaN).
  void Apply(int64_t t_us, const motion::Pose2D& sensor, const std::vector<float>& angles, double max_range_m,
             std::vector<float>* ranges);
  long long glass_beams() const { return glass_beams_; }    // beams that went through glass
  long long person_beams() const { return person_beams_; }  // beams a person stopped

 private:
  struct Person {
    double x = 0, y = 0, vx = 0, vy = 0;
    int64_t until_us = -1;  // walks until then; -1: not placed yet
  };
  void Place(Person* p, int64_t t_us, const motion::Pose2D& sensor);
  bool Glass(double x, double y) const;

  ScanPerturbationOptions o_;
  uint64_t seed_;
  std::mt19937_64 rng_;
  std::vector<Person> people_;
  int64_t last_us_ = -1;
  long long glass_beams_ = 0, person_beams_ = 0;
};

}  // namespace mbot::mapping
