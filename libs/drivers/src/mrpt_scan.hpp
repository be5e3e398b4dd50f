// An MRPT 2D range scan as the project's LidarScan: invalid ranges become 0 (no return), angles
// counter-clockwise in the sensor frame, the sensor's pose on the robot. Shared by the rawlog
// source and the simplemap reader.
#pragma once

#include <mrpt/obs/CObservation2DRangeScan.h>

#include "mbot/msgs/events.hpp"

namespace mbot::drivers {

using namespace msgs;  // the event vocabulary

inline LidarScan FromMrptScan(const mrpt::obs::CObservation2DRangeScan& scan) {
  LidarScan s;
  const size_t n = scan.getScanSize();
  s.ranges_m.resize(n);
  s.angles_rad.resize(n);
  for (size_t i = 0; i < n; ++i) {
    s.ranges_m[i] = scan.getScanRangeValidity(i) ? scan.getScanRange(i) : 0.0f;
    s.angles_rad[i] = static_cast<float>(scan.getScanAngle(i));
  }
  s.max_range_m = scan.maxRange;
  s.sensor_pose = {scan.sensorPose.x(), scan.sensorPose.y(), scan.sensorPose.yaw()};
  return s;
}

}  // namespace mbot::drivers
