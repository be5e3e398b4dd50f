// The pose graph in g2o's format against MRPT's own reader, writer and optimiser (an independent
// implementation of the format): what we write MRPT reads to the bit, what MRPT writes we read, and
// the graph we write solves to the same poses under MRPT's sparse Levenberg–Marquardt as under our
// Ceres solve. Bad files are refused naming the line.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <mrpt/graphs/CNetworkOfPoses.h>
#include <mrpt/graphslam/levmarq.h>
#include <random>

#include "mbot/mapping/graph_slam.hpp"
#include "mbot/mapping/pose_graph.hpp"
#include "mbot/mapping/pose_graph_io.hpp"

namespace mbot::mapping {
namespace {

using motion::Pose2D;
namespace fs = std::filesystem;

std::string TempFile(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("mbot_g2o_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return (dir / name).string();
}

// Graph SLAM's layout: a loop of 40 nodes around a 4 × 4 m square with drifting odometry, two
// submaps and two loop closures of the last nodes against the first submap.
struct SquareLoop {
  std::vector<Pose2D> truth, nodes, submaps;
  std::vector<PoseConstraint> constraints;
  SquareLoop() {
    for (int side = 0; side < 4; ++side)
      for (int k = 0; k < 10; ++k) {
        const Pose2D corner = Pose2D{0, 0, side * M_PI / 2}.Compose({0, 0, 0});
        const double xs[4] = {0, 4, 4, 0}, ys[4] = {0, 0, 4, 4};
        truth.push_back(
            {xs[side] + std::cos(corner.theta) * 0.4 * k, ys[side] + std::sin(corner.theta) * 0.4 * k, corner.theta});
      }
    std::mt19937 rng(3);
    std::normal_distribution<double> n(0, 0.02);
    nodes.push_back(truth[0]);
    for (size_t i = 1; i < truth.size(); ++i) {
      Pose2D step = truth[i - 1].Inverse().Compose(truth[i]);
      step.x += n(rng), step.y += n(rng), step.theta += n(rng);
      nodes.push_back(nodes.back().Compose(step));
      constraints.push_back({PoseConstraint::kOdometry, int(i) - 1, int(i), step, 1e3, 1e3, 0});
    }
    submaps = {truth[0], truth[20]};
    for (int i : {0, 1, 2}) constraints.push_back({PoseConstraint::kIntraSubmap, 0, i, truth[i], 1e5, 1e5, 0});
    for (int i : {20, 21})
      constraints.push_back({PoseConstraint::kIntraSubmap, 1, i, truth[20].Inverse().Compose(truth[i]), 1e5, 1e5, 0});
    for (int i : {38, 39}) constraints.push_back({PoseConstraint::kLoopClosure, 0, i, truth[i], 1.1e4, 1e5, 0.7});
  }
};

TEST(G2o, WhatWeWriteMrptReadsToTheBit) {
  const SquareLoop g;
  const G2oGraph ours = ToG2o(g.nodes, g.submaps, g.constraints);
  const std::string path = TempFile("ours.g2o");
  WriteG2o(ours, path);
  mrpt::graphs::CNetworkOfPoses2DInf mrpt_graph;
  mrpt_graph.loadFromTextFile(path);
  ASSERT_EQ(mrpt_graph.nodes.size(), g.nodes.size() + g.submaps.size());
  ASSERT_EQ(mrpt_graph.edges.size(), g.constraints.size());
  for (size_t i = 0; i < g.nodes.size(); ++i) {
    const mrpt::poses::CPose2D& p = mrpt_graph.nodes.at(g.submaps.size() + i);
    EXPECT_EQ(p.x(), g.nodes[i].x);
    EXPECT_EQ(p.y(), g.nodes[i].y);
    EXPECT_EQ(p.phi(), g.nodes[i].theta);
  }
  // Loop closures: submap 0 to the last nodes, with their weights as the information.
  const auto range = mrpt_graph.edges.equal_range({0, g.submaps.size() + 39});
  ASSERT_NE(range.first, range.second);
  const mrpt::poses::CPosePDFGaussianInf& e = range.first->second;
  EXPECT_EQ(e.mean.x(), g.truth[39].x);
  EXPECT_EQ(e.mean.phi(), g.truth[39].theta);
  EXPECT_EQ(e.cov_inv(0, 0), 1.1e4);
  EXPECT_EQ(e.cov_inv(1, 1), 1.1e4);
  EXPECT_EQ(e.cov_inv(2, 2), 1e5);
  EXPECT_EQ(e.cov_inv(0, 1), 0.0);
}

TEST(G2o, WhatMrptWritesWeRead) {
  mrpt::graphs::CNetworkOfPoses2DInf m;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-3, 3);
  for (unsigned i = 0; i < 30; ++i) m.nodes[i] = mrpt::poses::CPose2D(u(rng), u(rng), u(rng) / 3);
  for (unsigned i = 1; i < 30; ++i) {
    mrpt::poses::CPosePDFGaussianInf e;
    e.mean = mrpt::poses::CPose2D(u(rng), u(rng), u(rng) / 3);
    e.cov_inv.setIdentity();
    e.cov_inv(0, 0) = 100 + i, e.cov_inv(1, 1) = 50, e.cov_inv(2, 2) = 400;
    e.cov_inv(0, 1) = e.cov_inv(1, 0) = 3.5;
    e.cov_inv(1, 2) = e.cov_inv(2, 1) = -1.25;
    m.insertEdge(i - 1, i, e);
  }
  const std::string path = TempFile("mrpt.g2o");
  m.saveToTextFile(path);
  const G2oGraph g = ReadG2o(path);
  ASSERT_EQ(g.vertices.size(), 30u);
  ASSERT_EQ(g.edges.size(), 29u);
  EXPECT_EQ(g.submaps, -1);       // not one of ours
  ASSERT_EQ(g.fixed.size(), 1u);  // MRPT writes its root as FIX
  EXPECT_EQ(g.fixed[0], 0);
  for (const G2oVertex& v : g.vertices) {
    const mrpt::poses::CPose2D& p = m.nodes.at(v.id);
    EXPECT_NEAR(v.pose.x, p.x(), 1e-5);  // MRPT prints 6 significant digits
    EXPECT_NEAR(v.pose.theta, p.phi(), 1e-5);
  }
  for (const G2oEdge& e : g.edges) {
    ASSERT_EQ(e.to, e.from + 1);
    EXPECT_NEAR(e.information[0], 100 + e.to, 1e-9);
    EXPECT_NEAR(e.information[1], 3.5, 1e-9);
    EXPECT_NEAR(e.information[2], 0.0, 1e-9);
    EXPECT_NEAR(e.information[3], 50, 1e-9);
    EXPECT_NEAR(e.information[4], -1.25, 1e-9);
    EXPECT_NEAR(e.information[5], 400, 1e-9);
  }
}

TEST(G2o, OurSolveAndMrptsAgreeOnTheGraphWeWrite) {
  const SquareLoop g;
  const std::string path = TempFile("solve.g2o");
  WriteG2o(ToG2o(g.nodes, g.submaps, g.constraints), path);

  // Ours: the pose graph solve of graph SLAM, and the generic solve of the file read back.
  std::vector<Pose2D> nodes = g.nodes, submaps = g.submaps;
  OptimizePoseGraph(&nodes, &submaps, g.constraints, PoseGraphOptions{1e9, 100, 1});  // no Huber in the format
  G2oGraph read = ReadG2o(path);
  EXPECT_EQ(read.submaps, 2);
  OptimizeG2o(&read, PoseGraphOptions{1e9, 100, 1});

  // MRPT's.
  mrpt::graphs::CNetworkOfPoses2DInf m;
  m.loadFromTextFile(path);
  m.root = 0;
  mrpt::graphslam::TResultInfoSpaLevMarq info;
  mrpt::containers::yaml params = mrpt::containers::yaml::Map();
  params["max_iterations"] = 200;
  mrpt::graphslam::optimize_graph_spa_levmarq(m, info, nullptr, params);

  double worst_mrpt = 0, worst_read = 0, moved = 0;
  for (size_t i = 0; i < nodes.size(); ++i) {
    const mrpt::poses::CPose2D& p = m.nodes.at(2 + i);
    worst_mrpt = std::max(worst_mrpt, std::hypot(p.x() - nodes[i].x, p.y() - nodes[i].y));
    const Pose2D& r = read.vertices[2 + i].pose;
    worst_read = std::max(worst_read, std::hypot(r.x - nodes[i].x, r.y - nodes[i].y));
    moved = std::max(moved, std::hypot(g.nodes[i].x - nodes[i].x, g.nodes[i].y - nodes[i].y));
  }
  EXPECT_GT(moved, 0.1);  // the solve did something
  EXPECT_LT(worst_mrpt, 1e-3);
  EXPECT_LT(worst_read, 1e-6);
}

TEST(G2o, BadFilesAreRefusedNamingTheLine) {
  auto refuse = [](const std::string& text, const std::string& expected) {
    const std::string path = TempFile("bad.g2o");
    std::ofstream(path) << text;
    try {
      ReadG2o(path);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  refuse("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 x 0\n", "bad.g2o:2: VERTEX_SE2: expected id x y theta");
  refuse("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 0 1 0 0\n", ":2: vertex 0 is defined twice");
  refuse("VERTEX_SE2 0 0 0 0\n\nEDGE_SE2 0 7 1 0 0 1 0 0 1 0 1\n", ":3: the edge names vertex 7");
  refuse("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\nEDGE_SE2 0 1 1 0 0 -1 0 0 1 0 1\n", ":3: the information");
  refuse("VERTEX_SE2 0 0 0 nan\n", ":1: VERTEX_SE2: expected id x y theta");
  refuse("VERTEX_XY 0 1 2\n", ":1: 'VERTEX_XY' is not an SE(2) pose-graph line");
  refuse("VERTEX_SE2 0 0 0 0 5\n", ":1: VERTEX_SE2: unexpected '5'");
  refuse("VERTEX_SE2 0 0 0 0\nFIX 3\n", "FIX names vertex 3");
}

// Graph SLAM's own graph: written after a run, read by MRPT, solved again to the same poses.
TEST(G2o, GraphSlamsGraphReadsBackAndIsAlreadySolved) {
  OccupancyGrid world(120, 120, 0.05, 0, 0, -100);
  for (int i = 0; i < 120; ++i) world.at(i, 0) = world.at(i, 119) = world.at(0, i) = world.at(119, i) = 100;
  for (int i = 50; i < 70; ++i) world.at(i, 60) = 100;  // stubs inside the loop
  for (int i = 40; i < 52; ++i) world.at(60, i) = 100;
  GraphSlamOptions o;
  o.background = false;
  o.nodes_per_submap = 10;
  o.optimize_every_nodes = 10;
  MapperOptions map;
  map.center_x_m = 3, map.center_y_m = 3;
  GraphSlam slam(o, map);
  slam.Initialize({1, 3, -M_PI / 2}, {});
  Pose2D odometry;
  for (int k = 0; k < 120; ++k) {
    const double a = k * 2 * M_PI / 120;
    const Pose2D truth{3 - 2 * std::cos(a), 3 - 2 * std::sin(a) * 0.9, a - M_PI / 2};
    if (k > 0) {
      const double ap = (k - 1) * 2 * M_PI / 120;
      const Pose2D prev{3 - 2 * std::cos(ap), 3 - 2 * std::sin(ap) * 0.9, ap - M_PI / 2};
      odometry = odometry.Compose(prev.Inverse().Compose(truth));
    }
    std::vector<ScanRay> rays;
    for (int b = 0; b < 360; ++b) {
      const double ang = truth.theta + b * M_PI / 180;
      double r = 0;
      int cx, cy;
      do {
        r += 0.01;
        world.WorldToCell(truth.x + r * std::cos(ang), truth.y + r * std::sin(ang), &cx, &cy);
      } while (world.at(cx, cy) <= 0 && r < 10);
      rays.push_back({0, 0, float(r * std::cos(b * M_PI / 180)), float(r * std::sin(b * M_PI / 180)), true});
    }
    slam.ProcessScan(rays, odometry);
  }
  slam.Finish();
  const G2oGraph graph = slam.Graph();
  const std::string path = TempFile("slam.g2o");
  WriteG2o(graph, path);
  mrpt::graphs::CNetworkOfPoses2DInf m;
  m.loadFromTextFile(path);
  EXPECT_EQ(m.nodes.size(), static_cast<size_t>(slam.stats().nodes + slam.stats().submaps));
  EXPECT_GT(m.edges.size(), m.nodes.size());
  G2oGraph read = ReadG2o(path);
  EXPECT_EQ(read.submaps, slam.stats().submaps);
  OptimizeG2o(&read, PoseGraphOptions{1e9, 50, 1});
  double worst = 0;
  for (size_t i = 0; i < read.vertices.size(); ++i)
    worst = std::max(worst, std::hypot(read.vertices[i].pose.x - graph.vertices[i].pose.x,
                                       read.vertices[i].pose.y - graph.vertices[i].pose.y));
  EXPECT_LT(worst, 0.01);

  // The map again at 2 cm: the same room, two and a half times as many cells a side.
  const OccupancyGrid fine = slam.RenderMap(0.02);
  EXPECT_DOUBLE_EQ(fine.resolution(), 0.02);
  EXPECT_NEAR(fine.width() * 0.02, slam.map().width() * slam.map().resolution(), 5.0);
  int cx, cy;
  fine.WorldToCell(3.0, 2.3, &cx, &cy);  // the stub at x = 60 cells · 0.05 m
  int best = -128;
  for (int d = -2; d <= 2; ++d) best = std::max<int>(best, fine.at(cx + d, cy));
  EXPECT_GT(best, 0);
}

}  // namespace
}  // namespace mbot::mapping
