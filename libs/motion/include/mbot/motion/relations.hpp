// The relative-pose metric of Kümmerle et al., "On measuring the accuracy of SLAM algorithms"
// (Autonomous Robots 27, 2009): a `.relations` file lists hand-checked relative motions between
// pairs of timestamps (`t1 t2 x y z roll pitch yaw`, only x, y and yaw used in 2D); a trajectory is
// scored by the error e = δ*⁻¹ ⊕ (x₁⁻¹ ⊕ x₂) of each relation, reported as the mean ± standard
// deviation of |e_trans|, |e_rot| and their squares, as the benchmark papers (Hess et al. 2016,
// Table II) print them.
#pragma once

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "mbot/motion/pose2d.hpp"

namespace mbot::motion {

struct Relation {
  int64_t t1_us = 0, t2_us = 0;
  Pose2D delta;  // the motion from the pose at t1 to the pose at t2, in t1's frame
  int line = 0;  // in the file
};

struct RelationsError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Reads a `.relations` file; a line that is not eight numbers is a RelationsError naming the file
// and line. Blank lines and `#` comments are skipped.
std::vector<Relation> ReadRelations(const std::string& path);

struct MeanStd {
  double mean = 0, std = 0;
};

struct RelationErrors {
  int relations = 0;  // in the file
  int scored = 0;     // with a pose at both stamps
  MeanStd trans_m, rot_deg, trans_sq_m2, rot_sq_deg2;
  double max_trans_m = 0, max_rot_deg = 0;
};

// Scores `poses` (keyed by stamp in µs) on `relations`. A stamp matches a pose within
// `tolerance_us`. Relations whose stamps both lie outside the trajectory's time span are not
// scored; a stamp inside the span with no pose is a RelationsError naming `source` (the relations
// file) and the first unmatched stamp, as is a trajectory that matches none of the relations.
RelationErrors ScoreRelations(const std::vector<Relation>& relations, const std::map<int64_t, Pose2D>& poses,
                              const std::string& source, int64_t tolerance_us = 1000);

}  // namespace mbot::motion
