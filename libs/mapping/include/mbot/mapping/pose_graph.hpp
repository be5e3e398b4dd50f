// The pose graph of graph SLAM: scan nodes and submap origins as SE(2) poses, tied by relative-pose
// constraints (a node's pose in a submap's frame: from the front end for the submaps it was
// inserted into, from the loop-closure search for older ones; consecutive nodes' relative motion by
// the front end and by odometry),
// solved with Ceres (sparse Cholesky) with the first submap held fixed. Loop closures carry a
// Huber loss, so a false one is down-weighted instead of bending the map; after a solve, those whose
// residual lies beyond the loss's scale are reported as rejected.
#pragma once

#include <cstdint>
#include <vector>

#include "mbot/motion/pose2d.hpp"

namespace mbot::mapping {

struct PoseConstraint {
  enum Kind { kIntraSubmap, kLoopClosure, kConsecutive, kOdometry };
  Kind kind = kIntraSubmap;
  // kIntraSubmap, kLoopClosure: a submap index; kConsecutive (the front end's relative motion) and
  // kOdometry (the odometry's): a node index.
  int from = 0;
  int to = 0;               // node index
  motion::Pose2D relative;  // `to` in the frame of `from`
  double translation_weight = 1.0, rotation_weight = 1.0;
  double score = 0;  // the match score (loop closures)
};

struct PoseGraphOptions {
  double huber_scale = 1.0;  // on loop closures' weighted residuals
  int max_iterations = 50;
  int threads = 1;
};

struct PoseGraphSummary {
  double initial_cost = 0, final_cost = 0;
  int iterations = 0;
  double seconds = 0;
  std::vector<int> rejected;  // indices into the constraints of loop closures beyond the Huber scale
};

// Optimises `nodes` and `submaps` in place under `constraints`; submaps[0] stays fixed.
PoseGraphSummary OptimizePoseGraph(std::vector<motion::Pose2D>* nodes, std::vector<motion::Pose2D>* submaps,
                                   const std::vector<PoseConstraint>& constraints, const PoseGraphOptions& options);

inline bool BetweenNodes(const PoseConstraint& c) {
  return c.kind == PoseConstraint::kConsecutive || c.kind == PoseConstraint::kOdometry;
}

// The constraint's weighted residual norm at the given poses.
double ConstraintResidual(const PoseConstraint& c, const std::vector<motion::Pose2D>& nodes,
                          const std::vector<motion::Pose2D>& submaps);

}  // namespace mbot::mapping
