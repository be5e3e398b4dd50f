// Scans at known poses into an occupancy grid (an MRPT simplemap's keyframes): mapping's work,
// which the readers of libs/drivers reach through this interface. libs/mapping provides it at
// start (mapping::RegisterScanRenderer, named with mbot_register), so no I/O library links mapping.
#pragma once

#include <functional>
#include <vector>

#include "mbot/msgs/events.hpp"

namespace mbot::msgs {

struct PosedScan {
  Pose2D robot;    // where the robot was (map frame)
  LidarScan scan;  // one pose for the whole scan (a keyframe)
};

struct RenderedGrid {
  OccupancyGrid grid;
  int rejected_scans = 0;  // left out: non-finite poses or ranges, or a grid grown past its bound
};

// Renders `scans` at `resolution_m`; the grid starts round `centre` and grows as they need.
using ScanRenderer =
    std::function<RenderedGrid(const std::vector<PosedScan>& scans, double resolution_m, const Pose2D& centre)>;

void SetScanRenderer(ScanRenderer renderer);
// nullptr until a library set one.
const ScanRenderer* GetScanRenderer();

}  // namespace mbot::msgs
