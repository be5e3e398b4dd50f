// Graph SLAM's pieces: the matching field and its bounds, branch and bound against an exhaustive
// search, the Ceres fit, the pose graph with a true and a false loop closure, and the whole system
// closing a loop in a simulated building whose odometry drifts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "mbot/mapping/graph_slam.hpp"
#include "mbot/mapping/pose_graph.hpp"
#include "mbot/mapping/scan_matching.hpp"
#include "room_fixture.hpp"

namespace mbot::mapping {
namespace {

using motion::Pose2D;

// A 12 × 8 m floor at 5 cm: outer walls, a 6 × 2 m block in the middle (so the robot drives a loop
// around it) and pillars and notches that make every stretch look different.
OccupancyGrid Building() {
  OccupancyGrid g(240, 160, 0.05, 0.0, 0.0, -100);
  auto box = [&](double x0, double y0, double x1, double y1) {
    for (int y = static_cast<int>(y0 / 0.05); y < static_cast<int>(y1 / 0.05); ++y)
      for (int x = static_cast<int>(x0 / 0.05); x < static_cast<int>(x1 / 0.05); ++x) g.at(x, y) = 100;
  };
  box(0, 0, 12, 0.1), box(0, 7.9, 12, 8), box(0, 0, 0.1, 8), box(11.9, 0, 12, 8);
  box(3, 3, 9, 5);
  box(1.0, 1.0, 1.3, 1.3), box(6.0, 0.1, 6.2, 0.8), box(10.5, 6.2, 11.0, 6.5), box(4.0, 7.2, 4.8, 7.9);
  box(9.0, 3.5, 9.6, 3.9), box(2.2, 6.8, 2.4, 7.4), box(7.5, 0.8, 7.7, 1.0), box(11.3, 2.0, 11.9, 2.2);
  return g;
}

// What a 360-beam lidar (1° apart, as the Intel log's SICK) at `truth` sees in `world`, robot frame.
std::vector<ScanRay> ScanAt(const OccupancyGrid& world, const Pose2D& truth) { return MarchScan(world, truth, 360); }

// The largest distance between a trajectory and the truth, pose by pose.
double WorstError(const std::vector<Pose2D>& poses, const std::vector<Pose2D>& truth) {
  double worst = 0;
  for (size_t i = 0; i < poses.size() && i < truth.size(); ++i)
    worst = std::max(worst, std::hypot(poses[i].x - truth[i].x, poses[i].y - truth[i].y));
  return worst;
}

// The SLAM map that holds the building, with room around it.
MapperOptions BuildingMap() {
  MapperOptions map;
  map.width_m = 14, map.height_m = 10, map.center_x_m = 6, map.center_y_m = 4;
  return map;
}

// A drive along the building's long side, one pose every `step_m`.
std::vector<Pose2D> AlongTheLongSide(double step_m) {
  std::vector<Pose2D> truth;
  for (double d = 0; d < 8.4; d += step_m) truth.push_back({1.8 + d, 1.8, 0});
  return truth;
}

TEST(MatchGrid, LevelsBoundEveryBlock) {
  const OccupancyGrid world = Building();
  const MatchGrid grid(world, 0.05, 0, 5);
  ASSERT_EQ(grid.levels(), 5);
  std::mt19937 rng(3);
  for (int k = 0; k < 2000; ++k) {
    const int h = 1 + static_cast<int>(rng() % 4);
    const int x = static_cast<int>(rng() % (world.width() + 20)) - 20,
              y = static_cast<int>(rng() % (world.height() + 20)) - 20;
    int best = 0;
    for (int dy = 0; dy < (1 << h); ++dy)
      for (int dx = 0; dx < (1 << h); ++dx) best = std::max(best, grid.Bound(0, x + dx, y + dy));
    ASSERT_EQ(grid.Bound(h, x, y), best) << "level " << h << " at " << x << ", " << y;
  }
  // The field peaks on walls and fades within a few sigma.
  EXPECT_FLOAT_EQ(grid.At(0, 0), 1.0f);
  EXPECT_FLOAT_EQ(grid.At(40, 40), 0.0f);
}

TEST(BranchAndBound, FindsTheBestLatticePoseAsAnExhaustiveSearchDoes) {
  const OccupancyGrid world = Building();
  const MatchGrid grid(world, 0.05, 0, 7);
  const Pose2D truth{4.3, 1.7, 0.4};
  const std::vector<Point2> points = ScanHitPoints(ScanAt(world, truth));
  const Pose2D guess{4.3 + 0.42, 1.7 - 0.31, 0.4 + 0.12};
  const SearchWindow window{0.6, 0.2, 0.01};
  const MatchResult m = MatchBranchAndBound(grid, points, guess, window, 0.3);
  ASSERT_TRUE(m.found);
  EXPECT_NEAR(m.pose.x, truth.x, 0.051);
  EXPECT_NEAR(m.pose.y, truth.y, 0.051);
  EXPECT_NEAR(m.pose.theta, truth.theta, 0.011);
  // Exhaustive over the same lattice: nothing scores more.
  const int n_angles = static_cast<int>(std::ceil(window.angular_rad / 0.01)), wl = 12;
  double best = 0;
  int64_t all = 0;
  for (int a = -n_angles; a <= n_angles; ++a)
    for (int dx = -wl; dx <= wl; ++dx)
      for (int dy = -wl; dy <= wl; ++dy, ++all)
        best = std::max(best, grid.Score({guess.x + dx * 0.05, guess.y + dy * 0.05, guess.theta + a * 0.01}, points));
  EXPECT_NEAR(m.score, best, 1.0 / 255);
  EXPECT_LT(m.evaluated, all / 5) << "the bounds pruned little";
  // A bar no pose reaches: nothing found.
  EXPECT_FALSE(MatchBranchAndBound(grid, points, guess, window, std::min(1.0, best + 0.05)).found);
}

TEST(RefineMatch, SettlesOnTheTruthFromACellAway) {
  const OccupancyGrid world = Building();
  const MatchGrid grid(world, 0.05, 0, 1);
  const Pose2D truth{7.2, 6.1, -2.2};
  const std::vector<Point2> points = ScanHitPoints(ScanAt(world, truth));
  RefineOptions o;
  o.translation_weight = 0.1, o.rotation_weight = 0.1;  // the field decides
  const Pose2D fit = RefineMatch(grid, points, {7.2 + 0.04, 6.1 - 0.03, -2.2 + 0.02}, o);
  EXPECT_NEAR(fit.x, truth.x, 0.01);
  EXPECT_NEAR(fit.y, truth.y, 0.01);
  EXPECT_NEAR(fit.theta, truth.theta, 0.008);
}

// Nodes around a 4 m square whose measured relative motions turn 0.7° too little per step: the loop
// does not close until a loop closure says where the last node is.
TEST(PoseGraph, ALoopClosureClosesTheLoopAndAFalseOneIsRejected) {
  std::vector<Pose2D> truth;
  for (int i = 0; i < 16; ++i) {
    const int side = i / 4, k = i % 4;
    const double t = side * M_PI / 2;
    const Pose2D corner[4] = {{0, 0, 0}, {4, 0, M_PI / 2}, {4, 4, M_PI}, {0, 4, -M_PI / 2}};
    truth.push_back(corner[side].Compose({k * 1.0, 0, 0}));
    (void)t;
  }
  std::vector<PoseConstraint> c;
  std::vector<Pose2D> nodes{truth[0]}, submaps{truth[0]};
  for (size_t i = 1; i < truth.size(); ++i) {
    Pose2D rel = truth[i - 1].Inverse().Compose(truth[i]);
    rel.theta -= 0.012;
    c.push_back({PoseConstraint::kConsecutive, static_cast<int>(i - 1), static_cast<int>(i), rel, 1e5, 1e5, 0});
    nodes.push_back(nodes.back().Compose(rel));
  }
  c.push_back({PoseConstraint::kIntraSubmap, 0, 0, {}, 1e5, 1e5, 0});
  const double drift = std::hypot(nodes.back().x - truth.back().x, nodes.back().y - truth.back().y);
  ASSERT_GT(drift, 0.4);
  c.push_back({PoseConstraint::kLoopClosure, 0, 15, truth[0].Inverse().Compose(truth[15]), 1.1e4, 1e5, 0.9});
  std::vector<Pose2D> clean_nodes = nodes, clean_submaps = submaps;
  const PoseGraphSummary clean = OptimizePoseGraph(&clean_nodes, &clean_submaps, c, {10.0, 100, 1});
  EXPECT_LT(std::hypot(clean_nodes.back().x - truth.back().x, clean_nodes.back().y - truth.back().y), drift / 4);
  EXPECT_TRUE(clean.rejected.empty());
  // A false closure (node 8 said to be 2 m off) is down-weighted and reported.
  c.push_back({PoseConstraint::kLoopClosure, 0, 8, {1.0, 2.0, 0.3}, 1.1e4, 1e5, 0.6});
  std::vector<Pose2D> plain_nodes = nodes, plain_submaps = submaps;
  const PoseGraphSummary s = OptimizePoseGraph(&nodes, &submaps, c, {10.0, 100, 1});
  ASSERT_EQ(s.rejected.size(), 1u);
  EXPECT_EQ(c[s.rejected[0]].to, 8);
  // Without the robust loss (a scale no residual reaches) the same closure bends the graph far more.
  OptimizePoseGraph(&plain_nodes, &plain_submaps, c, {1e9, 100, 1});
  auto bent = [&](const std::vector<Pose2D>& v) {
    double most = 0;
    for (size_t i = 0; i < v.size(); ++i)
      most = std::max(most, std::hypot(v[i].x - clean_nodes[i].x, v[i].y - clean_nodes[i].y));
    return most;
  };
  EXPECT_GT(bent(plain_nodes), 0.5);
  EXPECT_LT(bent(nodes), 0.3 * bent(plain_nodes));
}

// Twice around the block with odometry that over-turns 3 % and over-drives 2 %: graph SLAM keeps
// every pose within 10 cm of the truth (odometry ends metres off) and closes loops to do it.
TEST(GraphSlam, ClosesTheLoopAroundABuildingBlock) {
  const OccupancyGrid world = Building();
  std::vector<Pose2D> truth;
  const Pose2D corners[4] = {{1.8, 1.8, 0}, {10.2, 1.8, M_PI / 2}, {10.2, 6.2, M_PI}, {1.8, 6.2, -M_PI / 2}};
  const double lengths[4] = {8.4, 4.4, 8.4, 4.4};
  for (int lap = 0; lap < 2; ++lap) {
    for (int side = 0; side < 4; ++side) {
      for (double d = 0; d < lengths[side]; d += 0.1) truth.push_back(corners[side].Compose({d, 0, 0}));
      for (double a = 0.1; a < M_PI / 2; a += 0.1)
        truth.push_back(corners[(side + 1) % 4].Compose({0, 0, a - M_PI / 2}));
    }
  }
  GraphSlamOptions o;
  o.background = false;
  o.nodes_per_submap = 25;
  o.optimize_every_nodes = 25;
  o.loop_window = {1.0, 0.3, 0.01};
  o.loop_every_nodes = 2;
  o.loop_max_distance_m = 6.0;
  GraphSlam slam(o, BuildingMap());
  Pose2D odometry{0, 0, 0};
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.005);
  slam.Initialize(truth[0], odometry);
  for (size_t i = 0; i < truth.size(); ++i) {
    if (i > 0) {
      Pose2D step = truth[i - 1].Inverse().Compose(truth[i]);
      step.x *= 1.02, step.theta *= 1.03;
      step.x += noise(rng), step.theta += noise(rng);
      odometry = odometry.Compose(step);
    }
    slam.ProcessScan(ScanAt(world, truth[i]), odometry);
  }
  const Pose2D odometry_end = truth[0].Compose(odometry);
  ASSERT_GT(std::hypot(odometry_end.x - truth.back().x, odometry_end.y - truth.back().y), 1.0);
  slam.Finish();
  const std::vector<Pose2D> poses = slam.Trajectory();
  ASSERT_EQ(poses.size(), truth.size());
  EXPECT_LT(WorstError(poses, truth), 0.10);
  EXPECT_GT(slam.stats().loop_closures, 10);
  EXPECT_GT(slam.stats().submaps, 4);
  EXPECT_EQ(slam.stats().scans, static_cast<int>(truth.size()));
  // The rendered map has the block's walls where they are.
  const OccupancyGrid& m = slam.map();
  int cx, cy;
  m.WorldToCell(6.0, 3.02, &cx, &cy);
  EXPECT_GT(std::max({m.at(cx, cy), m.at(cx, cy - 1), m.at(cx, cy + 1)}), 0);
}

TEST(GraphSlam, CountsScansTooSparseToMatch) {
  GraphSlamOptions o;
  o.background = false;
  o.min_points = 50;
  GraphSlam slam(o, MapperOptions{});
  slam.Initialize({}, {});
  std::vector<ScanRay> few(10, ScanRay{0, 0, 1.0f, 0.0f, true});
  slam.ProcessScan(few, {});
  slam.ProcessScan(few, {0.2, 0, 0});
  EXPECT_EQ(slam.stats().sparse_scans, 2);
  const std::vector<Pose2D> poses = slam.Trajectory();
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_NEAR(poses[1].x, 0.2, 1e-9);  // it follows odometry
}

// An odometry glitch: halfway along the building's long side the odometry jumps 0.8 m sideways and
// stays jumped. The local window (±0.1 m) cannot reach the truth; the recovery search does, and the
// track stays on the truth. Without it the scans after the glitch are placed 0.8 m off.
double WorstErrorAfterAGlitch(double recover_below, int* recoveries, bool sparse_glitch_scan = false) {
  const OccupancyGrid world = Building();
  std::vector<Pose2D> truth = AlongTheLongSide(0.1);
  GraphSlamOptions o;
  o.background = false;
  o.recover_below = recover_below;
  GraphSlam slam(o, BuildingMap());
  slam.Initialize(truth[0], {});
  const Pose2D glitch{0.0, 0.8, 0.0};
  for (size_t i = 0; i < truth.size(); ++i) {
    Pose2D odometry = truth[0].Inverse().Compose(truth[i]);
    if (i >= truth.size() / 2) odometry = glitch.Compose(odometry);
    std::vector<ScanRay> scan = ScanAt(world, truth[i]);
    if (sparse_glitch_scan && i == truth.size() / 2) scan.resize(10);  // too few hits to match
    slam.ProcessScan(scan, odometry);
  }
  slam.Finish();
  *recoveries = slam.stats().recoveries;
  std::vector<Pose2D> poses = slam.Trajectory(), kept_truth = truth;
  if (sparse_glitch_scan) {  // that scan follows its odometry: the scans after it are the measure
    poses.erase(poses.begin() + truth.size() / 2);
    kept_truth.erase(kept_truth.begin() + truth.size() / 2);
  }
  return WorstError(poses, kept_truth);
}

// Across an odometry gap the clock bounds the search: the robot drives along the building at
// 1 m/s (scans at 20 Hz), and at one scan its true pose is 0.8 m to the side of what the odometry
// says, after a gap of `unobserved_s` (a restart when negative). The top speed learnt by then is
// about 1 m/s, so twice that over the 0.15 s since the last scan (0.3 m) plus the 0.3 m slack
// cannot reach 0.8 m, over 1.05 s it can; a restart searches the whole window. Returns the front
// end's error at that scan, as it published it (a loop closure may mend the graph later).
double FrontEndErrorAfterAGap(double unobserved_s, double speed_factor, int* bounded) {
  const OccupancyGrid world = Building();
  const std::vector<Pose2D> truth = AlongTheLongSide(0.05);
  GraphSlamOptions o;
  o.background = false;
  o.recover_speed_factor = speed_factor;
  GraphSlam slam(o, BuildingMap());
  slam.Initialize(truth[0], {});
  const size_t gap = truth.size() * 4 / 5;  // after 6.7 s: 114 spans of 1-2 s to learn the speed from
  const Pose2D side{0.0, 0.8, 0.0};
  double t = 0, error = 0;
  for (size_t i = 0; i <= gap; ++i) {
    t += 0.05;
    OdometryDoubt doubt;
    Pose2D at = truth[i];
    if (i == gap) {
      doubt = {true, unobserved_s};
      t += std::max(0.0, unobserved_s);
      at = side.Compose(truth[i]);  // where the robot is: the odometry missed it
    }
    const Pose2D published = slam.ProcessScan(ScanAt(world, at), truth[0].Inverse().Compose(truth[i]), doubt, t);
    error = std::hypot(published.x - at.x, published.y - at.y);
  }
  *bounded = slam.stats().doubtful_bounded;
  return error;
}

TEST(GraphSlam, ARecoveryAcrossAGapReachesNoFartherThanTheClockAllows) {
  int bounded = 0;
  EXPECT_GT(FrontEndErrorAfterAGap(0.1, 2.0, &bounded), 0.5);  // 0.8 m in 0.15 s: not the same robot
  EXPECT_EQ(bounded, 1);
  EXPECT_LT(FrontEndErrorAfterAGap(1.0, 2.0, &bounded), 0.05);   // 0.8 m in 1 s: within reach
  EXPECT_EQ(bounded, 0);                                         // 2 m + 0.3 m: the whole window
  EXPECT_LT(FrontEndErrorAfterAGap(-1.0, 2.0, &bounded), 0.05);  // a restart: anything goes
  EXPECT_EQ(bounded, 0);
  EXPECT_LT(FrontEndErrorAfterAGap(0.1, 0.0, &bounded), 0.05);  // no clock bound: the whole window
}

TEST(GraphSlam, ARecoverySearchFindsTheMotionAcrossAnOdometryGlitch) {
  int recoveries = 0;
  EXPECT_LT(WorstErrorAfterAGlitch(0.75, &recoveries), 0.05);
  EXPECT_EQ(recoveries, 1);
  EXPECT_GT(WorstErrorAfterAGlitch(0.0, &recoveries), 0.5);
  EXPECT_EQ(recoveries, 0);
  // The glitch on a scan too sparse to match: the next scan's search still reaches it (the odometry
  // since the last matched scan bounds the recovery window, not its own 0.1 m step).
  EXPECT_LT(WorstErrorAfterAGlitch(0.75, &recoveries, true), 0.05);
  EXPECT_EQ(recoveries, 1);
}

// A corridor the data cannot decide: a 30 m hall, 2 m wide, off a furnished room, seen by a 6 m
// lidar with 1 cm range noise. The robot drives from the room to the far end and back on the other
// side of the hall, on odometry that over-reads distance by 3 %. In the hall the scan fits the
// submap equally well anywhere along it, except that the submap's walls end where its last scans
// ended: trusted, the fit holds the robot back there and it stays put while it drives on. Kept to
// odometry along the hall (the scan's surfaces all face across it), the track is better than the
// odometry (the walls fix the heading; the hall's slow bend of about half a degree and the
// distance along it are what no scan can tell) and the closures in the room bound the rest.
OccupancyGrid Corridor() {
  OccupancyGrid g(700, 120, 0.05, 0.0, 0.0, -100);
  auto box = [&](double x0, double y0, double x1, double y1) {
    for (int y = static_cast<int>(y0 / 0.05); y < static_cast<int>(y1 / 0.05); ++y)
      for (int x = static_cast<int>(x0 / 0.05); x < static_cast<int>(x1 / 0.05); ++x) g.at(x, y) = 100;
  };
  box(0, 0, 4, 0.1), box(0, 5.9, 4, 6), box(0, 0, 0.1, 6);                    // the room
  box(4, 0, 4.1, 2), box(4, 4, 4.1, 6);                                       // its door to the hall
  box(1.0, 1.0, 1.4, 1.3), box(2.5, 4.5, 2.7, 5.2), box(3.2, 0.8, 3.5, 1.0);  // furniture
  box(4, 1.9, 34.9, 2), box(4, 4, 34.9, 4.1), box(34.8, 1.9, 34.9, 4.1);      // the hall and its end
  return g;
}

std::vector<ScanRay> ScanWithin(const OccupancyGrid& world, const Pose2D& truth, double max_range_m,
                                std::mt19937* rng) {
  std::normal_distribution<double> range_noise(0.0, 0.01);  // a SICK's, about
  // The beams do not start at the same angle on every scan (a spinning lidar is not synchronised
  // with the robot's motion), so two scans from one place do not hit the walls at the same points.
  const double offset = std::uniform_real_distribution<double>(0.0, M_PI / 180)(*rng);
  std::vector<ScanRay> rays;
  for (int k = 0; k < 360; ++k) {
    const double la = k * M_PI / 180 + offset, a = truth.theta + la;
    double r = 0;
    int cx, cy;
    bool hit = false;
    while (r < max_range_m) {
      r += 0.01;
      world.WorldToCell(truth.x + r * std::cos(a), truth.y + r * std::sin(a), &cx, &cy);
      if (world.at(cx, cy) > 0) {
        hit = true;
        break;
      }
    }
    if (hit) r += range_noise(*rng);
    rays.push_back(ScanRay{0, 0, float(r * std::cos(la)), float(r * std::sin(la)), hit});
  }
  return rays;
}

struct CorridorRun {
  double worst_m = 0, odometry_worst_m = 0;
  int degenerate = 0;
  int64_t contradicted = 0;  // closures a neighbouring submap placed elsewhere
};

CorridorRun DriveTheCorridor(double front_ratio) {
  const OccupancyGrid world = Corridor();
  std::vector<Pose2D> truth;
  for (double x = 1.5; x < 33.0; x += 0.1) truth.push_back({x, 3.0, 0});
  for (double a = 0.1; a < M_PI; a += 0.1) truth.push_back({33.0, 3.0, a});
  for (double y = 3.0; y > 2.7; y -= 0.1) truth.push_back({33.0, y, M_PI});  // back on the other side
  for (double x = 33.0; x > 1.5; x -= 0.1) truth.push_back({x, 2.7, M_PI});
  GraphSlamOptions o;
  o.background = false;
  o.nodes_per_submap = 25;
  o.optimize_every_nodes = 25;
  o.front_min_constraint_ratio = front_ratio;
  MapperOptions map;
  map.width_m = 36, map.height_m = 8, map.center_x_m = 17.5, map.center_y_m = 3;
  GraphSlam slam(o, map);
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.002);
  Pose2D odometry;
  CorridorRun out;
  slam.Initialize(truth[0], odometry);
  for (size_t i = 0; i < truth.size(); ++i) {
    if (i > 0) {
      Pose2D step = truth[i - 1].Inverse().Compose(truth[i]);
      step.x = step.x * 1.03 + noise(rng), step.theta += noise(rng);
      odometry = odometry.Compose(step);
    }
    const Pose2D o_pose = truth[0].Compose(odometry);
    out.odometry_worst_m = std::max(out.odometry_worst_m, std::hypot(o_pose.x - truth[i].x, o_pose.y - truth[i].y));
    slam.ProcessScan(ScanWithin(world, truth[i], 6.0, &rng), odometry);
  }
  slam.Finish();
  out.worst_m = WorstError(slam.Trajectory(), truth);
  out.degenerate = slam.stats().degenerate_scans;
  out.contradicted = slam.stats().loop_closures_contradicted;
  return out;
}

TEST(GraphSlam, ACorridorTheDataCannotDecideKeepsToOdometryAlongIt) {
  const CorridorRun kept = DriveTheCorridor(GraphSlamOptions{}.front_min_constraint_ratio);
  const CorridorRun trusted = DriveTheCorridor(0.0);
  ::testing::Test::RecordProperty("kept_worst_m", std::to_string(kept.worst_m));
  ::testing::Test::RecordProperty("odometry_worst_m", std::to_string(kept.odometry_worst_m));
  ::testing::Test::RecordProperty("trusted_worst_m", std::to_string(trusted.worst_m));
  // Measured: kept 0.32 m worst (odometry's own 1.19 m), trusted 6.8 m.
  EXPECT_GT(kept.degenerate, 300);
  EXPECT_LT(kept.worst_m, kept.odometry_worst_m);
  EXPECT_LT(kept.worst_m, 0.6);
  EXPECT_EQ(trusted.degenerate, 0);
  EXPECT_GT(trusted.worst_m, 2.0);
  // Closures a neighbouring submap contradicted across the hall (2026-12-05: 20 of 843; without the
  // check the worst error was 0.362 m against 0.371 m with it).
  ::testing::Test::RecordProperty("kept_closures_contradicted", std::to_string(kept.contradicted));
}

// Three corridors side by side, 0.6 m apart and alike to the centimetre (a maze's): the robot drives
// east along the first, turns through the gap at its end and drives west along the second. Each of
// the second's scans fits the first corridor's finished submaps perfectly 0.6 m to the south.
OccupancyGrid Corridors() {
  OccupancyGrid g(150, 60, 0.05, 0.0, 0.0, -100);
  auto box = [&](double x0, double y0, double x1, double y1) {
    for (int y = static_cast<int>(std::lround(y0 / 0.05)); y < static_cast<int>(std::lround(y1 / 0.05)); ++y)
      for (int x = static_cast<int>(std::lround(x0 / 0.05)); x < static_cast<int>(std::lround(x1 / 0.05)); ++x)
        g.at(x, y) = 100;
  };
  box(0.0, 0.0, 7.5, 0.5), box(0.0, 2.4, 7.5, 3.0), box(0.0, 0.0, 0.5, 3.0), box(7.0, 0.0, 7.5, 3.0);
  box(0.5, 1.05, 6.4, 1.15);                 // between the first and second corridors: a gap at the east end
  box(1.1, 1.65, 7.0, 1.75);                 // between the second and third: a gap at the west end
  for (double x = 1.0; x < 6.5; x += 0.7) {  // alcoves and pillars, the same in every corridor
    for (double y : {0.5, 1.15, 1.75}) box(x, y, x + 0.2, y + 0.1);
  }
  return g;
}

struct LookAlikeRun {
  double worst_m = 0;
  int64_t closures = 0, bounded = 0;
};

LookAlikeRun DriveAlongLookAlikes(double drift_m_per_m) {
  const OccupancyGrid world = Corridors();
  std::vector<Pose2D> truth;
  for (double x = 1.0; x < 6.7; x += 0.05) truth.push_back({x, 0.8, 0.0});
  for (double a = 0.1; a < M_PI; a += 0.1) truth.push_back({6.7 + 0.3 * std::sin(a), 1.1 - 0.3 * std::cos(a), a});
  for (double x = 6.7; x > 1.0; x -= 0.05) truth.push_back({x, 1.4, M_PI});
  GraphSlamOptions o;
  o.background = false;
  o.nodes_per_submap = 15;
  o.optimize_every_nodes = 15;
  o.loop_every_nodes = 1;
  o.loop_drift_m_per_m = drift_m_per_m;
  o.loop_drift_rad_per_m = drift_m_per_m / 2;
  MapperOptions map;
  map.width_m = 9, map.height_m = 5, map.center_x_m = 3.75, map.center_y_m = 1.5;
  GraphSlam slam(o, map);
  slam.Initialize(truth[0], {});
  for (const Pose2D& t : truth) slam.ProcessScan(ScanAt(world, t), truth[0].Inverse().Compose(t));
  slam.Finish();
  LookAlikeRun run;
  run.worst_m = WorstError(slam.Trajectory(), truth);
  run.closures = slam.stats().loop_closures;
  run.bounded = slam.stats().loop_searches_bounded;
  return run;
}

TEST(GraphSlam, ALookAlikeCorridorFartherThanTheDriftIsNotClosedOn) {
  const LookAlikeRun bounded = DriveAlongLookAlikes(GraphSlamOptions{}.loop_drift_m_per_m);
  const LookAlikeRun unbounded = DriveAlongLookAlikes(0.0);
  ::testing::Test::RecordProperty("bounded_worst_m", std::to_string(bounded.worst_m));
  ::testing::Test::RecordProperty("unbounded_worst_m", std::to_string(unbounded.worst_m));
  ::testing::Test::RecordProperty("unbounded_closures", std::to_string(unbounded.closures));
  // Measured: bounded 0.10 m worst (the front end's own drift; 735 searches narrowed), unbounded
  // 0.58 m: the second corridor folded onto the first.
  EXPECT_GT(bounded.bounded, 0);
  EXPECT_LT(bounded.worst_m, 0.15);
  EXPECT_EQ(unbounded.bounded, 0);
  EXPECT_GT(unbounded.worst_m, 0.4);
}

// A closure checked in a neighbouring submap: where the closure puts the node is where the
// neighbour finds it (confirmed), 0.14 m from it (contradicted: beyond the 0.1 m tolerance, with the
// search's 5 cm lattice), or the neighbour saw nothing of the place (unverifiable). In a corridor
// only the disagreement across it counts: 0.14 m along the hall is confirmed, 0.14 m across it is not.
TEST(VerifyClosure, ANeighbourConfirmsContradictsOrCannotTell) {
  GraphSlamOptions o;
  const OccupancyGrid building = Building();
  const MatchGrid field(building, o.field_sigma_m, 0, 3);
  const Pose2D truth{2.0, 6.5, 2.5};
  const std::vector<ScanRay> rays = ScanAt(building, truth);
  const std::vector<Point2> points = ScanHitPoints(rays), loop_points = ScanHitPoints(rays, 0.1);
  EXPECT_EQ(VerifyClosure(field, points, loop_points, truth, o), ClosureCheck::kConfirmed);
  EXPECT_EQ(VerifyClosure(field, points, loop_points, truth.Compose({0.05, 0.0, 0.0}), o), ClosureCheck::kConfirmed);
  EXPECT_EQ(VerifyClosure(field, points, loop_points, {truth.x + 0.14, truth.y, truth.theta}, o),
            ClosureCheck::kContradicted);
  EXPECT_EQ(VerifyClosure(field, points, loop_points, {truth.x, truth.y - 0.14, truth.theta}, o),
            ClosureCheck::kContradicted);
  const MatchGrid nothing(OccupancyGrid(240, 160, 0.05, 0.0, 0.0, -100), o.field_sigma_m, 0, 3);
  EXPECT_EQ(VerifyClosure(nothing, points, loop_points, truth, o), ClosureCheck::kUnverifiable);

  const OccupancyGrid hall = Corridor();
  const MatchGrid hall_field(hall, o.field_sigma_m, 0, 3);
  std::mt19937 rng(5);
  const Pose2D in_hall{18.0, 3.0, 0.0};
  const std::vector<ScanRay> hall_rays = ScanWithin(hall, in_hall, 6.0, &rng);
  const std::vector<Point2> hp = ScanHitPoints(hall_rays), hlp = ScanHitPoints(hall_rays, 0.1);
  EXPECT_EQ(VerifyClosure(hall_field, hp, hlp, {18.14, 3.0, 0.0}, o), ClosureCheck::kConfirmed);
  EXPECT_EQ(VerifyClosure(hall_field, hp, hlp, {18.0, 3.14, 0.0}, o), ClosureCheck::kContradicted);
}

// The window's law: the local window while the path is short, growing with it, never beyond the
// loop window; a recovery or doubtful odometry on the path opens it whole; rates of 0 switch it off.
TEST(LoopSearchWindow, GrowsWithThePathUpToTheLoopWindow) {
  GraphSlamOptions o;
  o.local_window = {0.1, 0.2, 0.005};
  o.loop_window = {3.0, 0.35, 0.005};
  o.loop_drift_m_per_m = 0.02, o.loop_drift_rad_per_m = 0.01;
  EXPECT_DOUBLE_EQ(LoopSearchWindow(o, 0.0, false).linear_m, 0.1);
  EXPECT_DOUBLE_EQ(LoopSearchWindow(o, 0.0, false).angular_rad, 0.2);
  EXPECT_DOUBLE_EQ(LoopSearchWindow(o, 10.0, false).linear_m, 0.3);
  EXPECT_DOUBLE_EQ(LoopSearchWindow(o, 10.0, false).angular_rad, 0.3);
  EXPECT_DOUBLE_EQ(LoopSearchWindow(o, 1000.0, false).linear_m, 3.0);
  EXPECT_DOUBLE_EQ(LoopSearchWindow(o, 1000.0, false).angular_rad, 0.35);
  EXPECT_DOUBLE_EQ(LoopSearchWindow(o, 1.0, true).linear_m, 3.0);
  EXPECT_DOUBLE_EQ(LoopSearchWindow(o, 1.0, true).min_angular_step_rad, 0.005);
  o.loop_drift_m_per_m = 0, o.loop_drift_rad_per_m = 0;
  EXPECT_DOUBLE_EQ(LoopSearchWindow(o, 1.0, false).linear_m, 3.0);
  EXPECT_DOUBLE_EQ(LoopSearchWindow(o, 1.0, false).angular_rad, 0.35);
}

// The recovery window's law: the odometry's step plus the slack (never below the local window,
// never beyond the recovery window); doubtful odometry with no reach by the clock, or a slack of
// 0, searches the whole recovery window.
TEST(RecoverySearchWindow, ReachesTheOdometrysStepPlusTheSlack) {
  GraphSlamOptions o;
  o.local_window = {0.1, 0.2, 0.005};
  o.recover_window = {1.5, 0.5, 0.005};
  o.recover_slack_m = 0.3;
  EXPECT_DOUBLE_EQ(RecoverySearchWindow(o, 0.05, false).linear_m, 0.35);
  EXPECT_DOUBLE_EQ(RecoverySearchWindow(o, 0.05, false).angular_rad, 0.5);
  EXPECT_DOUBLE_EQ(RecoverySearchWindow(o, 0.8, false).linear_m, 1.1);
  EXPECT_DOUBLE_EQ(RecoverySearchWindow(o, 3.0, false).linear_m, 1.5);
  EXPECT_DOUBLE_EQ(RecoverySearchWindow(o, 0.05, true).linear_m, 1.5);
  o.recover_slack_m = 0.01;
  EXPECT_DOUBLE_EQ(RecoverySearchWindow(o, 0.0, false).linear_m, 0.1);
  o.recover_slack_m = 0;
  EXPECT_DOUBLE_EQ(RecoverySearchWindow(o, 0.05, false).linear_m, 1.5);
}

// Across an odometry gap the step says little; the clock bounds the reach instead. A restart, or a
// reach not known, searches the whole window.
TEST(RecoverySearchWindow, ReachesAsFarAsTheClockAllowsAcrossAGap) {
  GraphSlamOptions o;
  o.local_window = {0.1, 0.2, 0.005};
  o.recover_window = {1.5, 0.5, 0.005};
  o.recover_slack_m = 0.3;
  EXPECT_DOUBLE_EQ(RecoverySearchWindow(o, 0.05, true, 0.4).linear_m, 0.7);
  EXPECT_DOUBLE_EQ(RecoverySearchWindow(o, 0.6, true, 0.4).linear_m, 0.9);  // the step, if longer
  EXPECT_DOUBLE_EQ(RecoverySearchWindow(o, 0.05, true, 5.0).linear_m, 1.5);
  EXPECT_DOUBLE_EQ(RecoverySearchWindow(o, 0.05, true, -1.0).linear_m, 1.5);
  EXPECT_DOUBLE_EQ(RecoverySearchWindow(o, 0.05, true).linear_m, 1.5);
}

// The top speed is a high percentile of the speed over 1-2 s spans of matched poses: unknown at
// first, then the robot's cruise, not a single wrong pose's jump; spans across a recovery or a
// clock that ran backwards are left out.
TEST(TopSpeed, IsTheMatchedPosesHighPercentileOverSpansOfASecond) {
  TopSpeed v;
  EXPECT_LT(v.Value(), 0);
  double t = 0, x = 0;
  auto drive = [&](double speed, double seconds) {
    for (int k = 0; k < seconds * 10; ++k) {
      t += 0.1;
      x += speed * 0.1;
      v.Add(t, {x, 0, 0}, true);
    }
  };
  drive(0.3, 10.0);
  EXPECT_LT(v.Value(), 0);  // fewer than 100 spans: the percentile would be the maximum
  drive(0.3, 30.0);
  EXPECT_NEAR(v.Value(), 0.3, 0.011);
  // A jump of 5 m with a recovery: not a span.
  x += 5;
  v.Add(t += 0.1, {x, 0, 0}, false);
  drive(0.3, 5.0);
  EXPECT_NEAR(v.Value(), 0.3, 0.011);
  // The clock runs back 100 s: the spans start again there (else every span would count as
  // 100 s long, and the speed as nothing).
  const int spans = v.spans();
  t -= 100;
  drive(0.3, 20.0);
  EXPECT_GE(v.spans(), spans + 180);
  EXPECT_NEAR(v.Value(), 0.3, 0.011);
  // Faster driving raises it once it is more than 1 % of the spans.
  drive(0.6, 60.0);
  EXPECT_NEAR(v.Value(), 0.6, 0.011);
}

// The measure itself: a room's scan faces every way, a corridor's across it only, whatever the
// scan's heading; the weak axis comes out along the corridor in the map's frame.
TEST(ScanTranslationConstraint, TellsACorridorFromARoom) {
  std::mt19937 rng(2);
  const Room room;
  const TranslationConstraint r = ScanTranslationConstraint(ScanHitPoints(room.rays), room.truth.theta);
  EXPECT_GT(r.ratio(), 0.5);
  const OccupancyGrid world = Corridor();
  for (double heading : {0.0, 0.7, 2.0}) {
    const Pose2D at{18.0, 3.0, heading};
    const TranslationConstraint c = ScanTranslationConstraint(ScanHitPoints(ScanWithin(world, at, 6.0, &rng)), heading);
    EXPECT_LT(c.ratio(), 0.003) << heading;
    EXPECT_LT(std::abs(std::sin(c.weak_axis_rad)), 0.05) << heading;  // along x, the hall's axis
  }
  // Near the room's door the scan sees the door's walls too: not a corridor any more.
  const TranslationConstraint door =
      ScanTranslationConstraint(ScanHitPoints(ScanWithin(world, {5.0, 3.0, 0.0}, 6.0, &rng)), 0.0);
  EXPECT_GT(door.ratio(), 0.01);
}
// The whole-map search: a scan from anywhere in the building, at any heading, is found where it was
// taken; a scan of another place is not found.
TEST(GlobalMatch, FindsAScanAnywhereOnTheMap) {
  const OccupancyGrid world = Building();
  for (const Pose2D& truth : {Pose2D{2.0, 6.5, 2.5}, Pose2D{10.3, 1.5, -1.0}, Pose2D{7.0, 2.2, 0.1}}) {
    const MatchResult m = GlobalMatch(world, ScanHitPoints(ScanAt(world, truth), 0.1), 0.05, 0, 0.6);
    ASSERT_TRUE(m.found);
    EXPECT_LT(std::hypot(m.pose.x - truth.x, m.pose.y - truth.y), 0.05);
    EXPECT_LT(std::abs(motion::WrapAngle(m.pose.theta - truth.theta)), 0.02);
  }
  const Room room;  // 4 m square, nothing like the building's 12 x 8 m floor
  EXPECT_FALSE(GlobalMatch(world, ScanHitPoints(room.rays, 0.1), 0.05, 0, 0.8).found);
}

}  // namespace
}  // namespace mbot::mapping
