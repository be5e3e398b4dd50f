// The log-odds occupancy grid every module shares is the message vocabulary's (libs/msgs); the
// mapping library builds, reads and draws it under this name.
#pragma once

#include "mbot/msgs/occupancy_grid.hpp"

namespace mbot::mapping {

using msgs::CropToKnown;
using msgs::kMaxGridCells;
using msgs::OccupancyGrid;

}  // namespace mbot::mapping
