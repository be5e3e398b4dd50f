// The pose graph in g2o's text format (Kümmerle et al., ICRA 2011), the exchange format of 2D pose
// graphs (g2o_viewer, MRPT's CNetworkOfPoses, GTSAM's readG2o, the public benchmark graphs):
//   VERTEX_SE2 id x y theta
//   EDGE_SE2 from to dx dy dtheta I11 I12 I13 I22 I23 I33   (the upper triangle of the information)
//   FIX id
// Graph SLAM's graph is written with its submap origins as vertices 0..S−1 and its scan nodes as
// S..S+N−1 (a comment line says so), submap 0 fixed; a constraint's information is diag(translation
// weight, translation weight, rotation weight), the same cost as the Ceres solve (the loop
// closures' Huber loss is not part of the format).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "mbot/mapping/pose_graph.hpp"
#include "mbot/motion/pose2d.hpp"

namespace mbot::mapping {

struct G2oVertex {
  int id = 0;
  motion::Pose2D pose;
};

struct G2oEdge {
  int from = 0, to = 0;
  motion::Pose2D relative;  // `to` in the frame of `from`
  // The upper triangle of the 3 × 3 information matrix: xx, xy, xθ, yy, yθ, θθ.
  std::array<double, 6> information{1, 0, 0, 1, 0, 1};
};

struct G2oGraph {
  std::vector<G2oVertex> vertices;
  std::vector<G2oEdge> edges;
  std::vector<int> fixed;
  int submaps = -1;  // graph SLAM's files: how many of the first vertices are submap origins (-1: unknown)
};

// Writes the file whole or not at all (throws naming the path).
void WriteG2o(const G2oGraph& graph, const std::string& path);
// Reads VERTEX_SE2 / EDGE_SE2 / FIX lines (and the older VERTEX2 / EDGE2, whose information is
// ordered xx, xy, yy, θθ, xθ, yθ); '#' starts a comment. Anything else, a malformed number, a
// duplicate vertex, an edge to a missing vertex or an information matrix that is not positive
// semi-definite on its diagonal is an error naming the file and line.
G2oGraph ReadG2o(const std::string& path);

// Graph SLAM's graph in that layout.
G2oGraph ToG2o(const std::vector<motion::Pose2D>& nodes, const std::vector<motion::Pose2D>& submaps,
               const std::vector<PoseConstraint>& constraints);
// Optimises the vertices of any SE(2) g2o graph with Ceres (full information matrices; the FIX
// vertices, or the first vertex when none is fixed, held constant). Returns the summary.
PoseGraphSummary OptimizeG2o(G2oGraph* graph, const PoseGraphOptions& options);

}  // namespace mbot::mapping
