// A lidar scan taken while the robot moves, turned into rays in the frame of the robot's pose at
// the end of the scan: each beam's sensor pose is interpolated between the robot's poses at the
// scan's start and end, so a particle only has to apply one rigid transform to every ray.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "mbot/motion/pose2d.hpp"

namespace mbot::mapping {

struct ScanRay {
  float ox = 0, oy = 0;  // where the beam left the sensor
  float ex = 0, ey = 0;  // its end point (the return, or the end of the cleared span)
  bool hit = false;      // false: max-range or no-return beam, clears space but marks no obstacle
};

struct ScanOptions {
  double min_range_m = 0.10;       // shorter returns hit the robot itself and are dropped
  double max_range_m = 0.0;        // returns at or beyond this are misses; 0: the sensor's own maximum
  double no_return_clear_m = 0.0;  // a beam with no return clears this far; 0: not at all
  // Range noise: each return becomes the mean of the returns of up to this many beams on either
  // side that lie within smooth_max_step_m of it (the same surface), so a flat wall's noise falls by
  // the square root of their count while an edge keeps its own side. 0: the ranges as measured.
  int smooth_beams = 0;
  double smooth_max_step_m = 0.05;
};

// No return: none measured (not finite, 0 or less), or the sensor's own maximum
// (`sensor_max_range_m`, 0 when unknown), which a SICK reports through glass or into the open (REP
// 117's out-of-range).
inline bool IsNoReturn(double range_m, double sensor_max_range_m) {
  return !std::isfinite(range_m) || range_m <= 0.0 || (sensor_max_range_m > 0 && range_m >= sensor_max_range_m);
}

// ranges, angles (counter-clockwise, sensor frame) and fractions (each beam's time within the scan,
// 0 = start, 1 = end) have one entry per beam. `start_in_end` is the robot's pose at the scan start
// expressed in the frame of its pose at the scan end; `sensor` is the sensor's pose on the robot.
// `sensor_max_range_m` is what the sensor reported (0 when unknown).
std::vector<ScanRay> DeskewScan(const std::vector<float>& ranges, const std::vector<float>& angles,
                                const std::vector<float>& fractions, const motion::Pose2D& start_in_end,
                                const motion::Pose2D& sensor, double sensor_max_range_m, const ScanOptions& options);

// When each beam of a scan was measured. kBeams: the scan's own per-beam times; kSpread: beams evenly
// over the time since the previous scan (a spinning lidar without usable beam times); kNone: all at
// the scan's time (no deskew); kAuto: beam times when they span at least half the scan period, else
// spread when the scan covers a turn and the period is under a second, else none.
enum class BeamTiming { kAuto, kBeams, kSpread, kNone };

struct BeamTimes {
  std::vector<float> fractions;      // per beam, 0 = the scan's start, 1 = its end; empty: no deskew
  int64_t duration_us = 0;           // from the scan's start to its end
  bool beam_times_unusable = false;  // kBeams was asked for, but the beam times do not span the scan
};

// `period_us`: the time since the previous scan (0 when unknown); `beam_times_us` empty when the
// source gives none.
BeamTimes TimeBeams(BeamTiming timing, const std::vector<float>& angles_rad, const std::vector<int64_t>& beam_times_us,
                    int64_t period_us);

}  // namespace mbot::mapping
