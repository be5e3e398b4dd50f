// [source] with type = sim: where the simulated robot starts, how long the run lasts, and the
// simulated robot's options (the keys are read from [source] only when the source is the simulator).
#pragma once

#include <optional>
#include <string>

#include "mbot/sim/sim_robot.hpp"
#include "mbot/motion/pose2d.hpp"

namespace mbot::config {
class Section;
}

namespace mbot::sim {

struct SimSourceOptions {
  // World frame. Unset: the world file's `start` pose (an `.arena` file's `pose start …` line);
  // a grid world has none, so it must be given.
  std::optional<motion::Pose2D> start;
  // `start = random`: a pose drawn from the reachable free space keeping random_start_clearance_m
  // from the walls (RandomFreePose), from the pipeline's seed — the Warehouse's random start.
  bool random_start = false;
  double random_start_clearance_m = 0.25;
  double duration_s = 600.0;  // simulated time after which the stream ends
  // 0: as fast as the pipeline consumes events; > 0: simulated time runs this many times the wall
  // clock (1: real time, for the simulated robot on the LCM bus).
  double realtime_factor = 0.0;
  SimRobotOptions robot;
};

// The simulated robot's model — motion, motors and firmware, IMU, lidar — from `section`: the keys
// ParseSimSourceOptions reads for it (sim_fidelity reads the same ones for the robot it measures).
void ParseSimRobotModel(config::Section& section, SimRobotOptions* robot);

// The robot a log recorded and the simulated one compared with it (sim_fidelity, fit_sim_model): its
// wheel constants, the simulator's model keys, its gyro's unit, its lidar's pose and range limits.
struct SimFidelityOptions;
SimFidelityOptions ParseSimFidelityOptions(config::Section& section);

// Reads the simulator's keys of [source]. Throws config::ConfigError naming the key.
SimSourceOptions ParseSimSourceOptions(config::Section& section);

}  // namespace mbot::sim
