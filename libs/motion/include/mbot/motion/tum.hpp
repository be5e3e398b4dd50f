// The TUM trajectory format's line: "t x y z qx qy qz qw" for a planar pose.
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

namespace mbot::motion {

// One TUM trajectory line for a planar pose at t seconds (z = 0, the heading as a yaw quaternion).
inline std::string TumLine(double t_s, double x, double y, double theta) {
  char line[160];
  std::snprintf(line, sizeof line, "%.6f %.6f %.6f 0 0 0 %.9f %.9f\n", t_s, x, y, std::sin(theta / 2),
                std::cos(theta / 2));
  return line;
}

// The comment line a TUM file of this project starts with, naming what it holds.
inline std::string TumHeader(const std::string& what) {
  return "# " + what + (what.empty() ? "" : ": ") + "t x y z qx qy qz qw\n";
}

}  // namespace mbot::motion
