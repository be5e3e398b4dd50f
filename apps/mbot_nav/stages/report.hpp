// Helpers the stages share for their printed lines and TUM files (JSON: libs/reports).
#pragma once

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "mbot/common/atomic_file.hpp"
#include "mbot/motion/pose2d.hpp"
#include "mbot/motion/tum.hpp"
#include "mbot/reports/json.hpp"

namespace mbot::app {

using motion::TumHeader;
using motion::TumLine;

// A number for a printed line (6 significant digits); non-finite values print as null.
using reports::Num;

// A TUM trajectory file (written whole or not at all): a comment line naming what it holds, then
// one line per pose, each composed onto `frame` (the identity: as given).
inline void WriteTum(const std::string& path, const std::string& what, const std::vector<motion::TimedPose>& poses,
                     const motion::Pose2D& frame = {}) {
  WriteFileAtomically(path, [&](std::ostream& o) {
    o << TumHeader(what);
    for (const motion::TimedPose& p : poses) {
      const motion::Pose2D w = frame.Compose(p.pose);
      o << TumLine(p.t_us * 1e-6, w.x, w.y, w.theta);
    }
  });
}

}  // namespace mbot::app
