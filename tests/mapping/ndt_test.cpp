// The normal-distributions transform over a log-odds map's hit moments (ndt.hpp) on the room
// fixture, whose walls' surfaces lie on cell borders: with 2.2 cm of range noise (the MBot's lidar)
// a wall's hits fill the two cells either side of its surface, a band over which a likelihood field
// of whole cells is flat, while the hits' Gaussians still place the scan to millimetres.
#include "mbot/mapping/ndt.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <utility>
#include <random>

#include "mbot/mapping/log_odds_mapper.hpp"
#include "mbot/mapping/particle_filter.hpp"
#include "mbot/mapping/slam.hpp"
#include "room_fixture.hpp"

namespace mbot::mapping {
namespace {

using motion::Pose2D;

constexpr double kDeg = M_PI / 180;

// The room's scan at `truth` with Gaussian range noise.
std::vector<ScanRay> NoisyScan(const Room& room, const Pose2D& truth, double sigma_m, std::mt19937* rng) {
  std::vector<ScanRay> rays = MarchScan(room.map, truth, 360);
  std::normal_distribution<double> noise(0.0, sigma_m);
  for (ScanRay& r : rays) {
    const double range = std::hypot(r.ex, r.ey), k = (range + noise(*rng)) / range;
    r.ex = static_cast<float>(r.ex * k), r.ey = static_cast<float>(r.ey * k);
  }
  return rays;
}

TEST(Ndt, PlacesANoisyScanBetweenCellsAndTheMomentsFollowAGrowingGrid) {
  const Room room;
  const Pose2D truth{0.6, -0.4, 0.3};
  MapperOptions mo;
  mo.hit_moments = true;
  mo.width_m = mo.height_m = 2.0;  // smaller than the room: the grid grows under the moments
  mo.center_x_m = truth.x, mo.center_y_m = truth.y;
  LogOddsMapper mapper(mo);
  std::mt19937 rng(7);
  for (int i = 0; i < 20; ++i) ASSERT_TRUE(mapper.Insert(NoisyScan(room, truth, 0.022, &rng), truth));
  // Then a return far to the south-west: the grid grows on its left and bottom, and every cell's
  // moments must move with it (the fits below would miss the walls otherwise).
  const int grown = mapper.grow_count();
  const Pose2D far = truth.Inverse().Compose(Pose2D{-8.0, -8.0, 0});
  ASSERT_TRUE(mapper.Insert({ScanRay{0, 0, float(far.x), float(far.y), true}}, truth));
  ASSERT_GT(mapper.grow_count(), grown);
  double hits = 0;
  for (int y = 0; y < mapper.moments().height(); ++y)
    for (int x = 0; x < mapper.moments().width(); ++x)
      for (int k = 0; k < HitMoments::kDirections; ++k) hits += mapper.moments().at(x, y, k).n;
  EXPECT_EQ(hits, 20 * 360 + 1);

  NdtOptions o;
  o.translation_weight = o.rotation_weight = 0.0;  // the scan alone
  o.occupied_threshold = 30;
  const std::vector<NdtPoint> points = NdtPoints(NoisyScan(room, truth, 0.022, &rng));
  for (const Pose2D start : {Pose2D{truth.x + 0.02, truth.y - 0.015, truth.theta + 1.5 * kDeg},
                             Pose2D{truth.x - 0.015, truth.y + 0.02, truth.theta - 2.0 * kDeg}}) {
    const NdtResult r = RefineNdt(mapper.map(), mapper.moments(), points, start, o);
    EXPECT_GT(r.points_used, 300);
    EXPECT_NEAR(r.pose.x, truth.x, 0.003);
    EXPECT_NEAR(r.pose.y, truth.y, 0.003);
    EXPECT_NEAR(r.pose.theta, truth.theta, 0.1 * kDeg);
  }
  // A map given whole has no hits' moments: nothing moves.
  LogOddsMapper given(mo);
  given.Reset(mapper.map());
  const Pose2D start{truth.x + 0.02, truth.y, truth.theta};
  const NdtResult none = RefineNdt(given.map(), given.moments(), points, start, o);
  EXPECT_EQ(none.points_used, 0);
  EXPECT_EQ(none.pose.x, start.x);
}

// MapperOptions::hit_range_power: a hit weighs (its range / 1 m)^power in its cell's moments, so a
// wall seen from afar is not outweighed by the hits the robot takes of it scan after scan from
// close by (the map then follows the robot's last poses; BENCHMARKS.md, maze 27).
TEST(Ndt, HitsWeighTheirRangeToThePowerInTheMoments) {
  constexpr double kHeading = 0.3;  // well inside a direction sector
  auto cell_after = [](double power) {
    MapperOptions mo;
    mo.hit_moments = true;
    mo.hit_range_power = power;
    mo.width_m = mo.height_m = 6.0;
    LogOddsMapper mapper(mo);
    // Three hits along one heading in the cell around (1.02, 0.52), away from its borders: from 2 m,
    // 1 cm past the cell's centre; from 0.5 m, 1 cm short of it; from 0.05 m (counted as 0.1 m), at it.
    int cx, cy;
    mapper.map().WorldToCell(1.02, 0.52, &cx, &cy);
    double mx, my;
    mapper.map().CellToWorld(cx, cy, &mx, &my);
    const double ux = std::cos(kHeading), uy = std::sin(kHeading);
    for (const auto& [range, past] : {std::pair{2.0, 0.01}, std::pair{0.5, -0.01}, std::pair{0.05, 0.0}}) {
      const Pose2D from{mx + (past - range) * ux, my + (past - range) * uy, kHeading};
      EXPECT_TRUE(mapper.Insert({ScanRay{0, 0, float(range), 0, true}}, from));
    }
    return mapper.moments().at(cx, cy, HitMoments::DirectionOf(kHeading));
  };
  const double ux = std::cos(kHeading);
  const CellMoments alike = cell_after(0.0);
  EXPECT_FLOAT_EQ(alike.n, 3.0f);
  EXPECT_FLOAT_EQ(alike.hits, 3.0f);
  EXPECT_NEAR(alike.sx / alike.n, 0.0, 1e-6);  // +1 cm, -1 cm and the centre
  const CellMoments squared = cell_after(2.0);
  EXPECT_FLOAT_EQ(squared.n, 4.0f + 0.25f + 0.01f);
  EXPECT_FLOAT_EQ(squared.hits, 3.0f);                                         // what min_hits counts
  EXPECT_NEAR(squared.sx / squared.n, (4.0 - 0.25) * 0.01 * ux / 4.26, 1e-6);  // the far view leads
  const CellMoments linear = cell_after(1.0);
  EXPECT_FLOAT_EQ(linear.n, 2.0f + 0.5f + 0.1f);
  // Full SLAM passes the refine's option to its mapper (slam.cpp); 2 unless a config says otherwise.
  // MazeAtTheMeasuredNoise fails with it at 0.
  EXPECT_EQ(NdtOptions{}.range_power, 2.0);
}

// Full SLAM from an empty map with the MBot's range noise and odometry whose heading drifts 0.3°
// per 5 cm: with the estimate fitted to the hits the heading stays within a few tenths of a degree.
TEST(Ndt, FullSlamWithTheRefinedEstimateHoldsTheHeadingUnderRangeNoise) {
  const Room room;
  auto run = [&](bool refine) {
    SlamOptions o;
    o.mode = SlamMode::kFullSlam;
    o.filter.particles = 300;
    o.mapper.width_m = o.mapper.height_m = 6.0;
    o.sensor.occupied_threshold = 30;
    o.refine_estimate = refine;
    Slam slam(o, 3);
    std::mt19937 rng(11);
    Pose2D truth{-0.5, -0.5, 0}, odometry = truth;
    slam.Initialize(truth, odometry);
    for (int i = 0; i < 10; ++i) slam.ProcessScan(NoisyScan(room, truth, 0.022, &rng), odometry);  // standing
    double worst = 0, worst_m = 0;
    for (int i = 1; i <= 40; ++i) {
      truth = truth.Compose(Pose2D{0.05, 0.0, (i <= 20 ? 2.0 : -2.0) * kDeg});
      odometry = odometry.Compose(Pose2D{0.05, 0.0, (i <= 20 ? 2.3 : -1.7) * kDeg});
      const SlamStep step = slam.ProcessScan(NoisyScan(room, truth, 0.022, &rng), odometry);
      worst = std::max(worst, std::abs(motion::WrapAngle(step.pose.theta - truth.theta)));
      worst_m = std::max(worst_m, std::hypot(step.pose.x - truth.x, step.pose.y - truth.y));
    }
    if (refine) {
      EXPECT_GT(slam.estimates_refined(), 30);
    }
    return std::make_pair(worst / kDeg, worst_m);
  };
  const auto refined = run(true), filter_alone = run(false);
  EXPECT_LT(refined.first, 0.3);
  EXPECT_LT(refined.second, 0.015);
  EXPECT_GT(filter_alone.first, 2 * refined.first) << "the fit made no difference";
}

// Shift moves every particle and the estimate rigidly: p <- correction ∘ p.
TEST(Ndt, ShiftMovesEveryParticleAndTheEstimateByTheCorrection) {
  ParticleFilterOptions po;
  po.particles = 50;
  ParticleFilter f(po, 5);
  f.InitializeAt({0.3, -0.2, 0.4}, 0.05, 0.1);
  const std::vector<Particle> before = f.particles();
  const Pose2D estimate = f.status().pose, correction{0.01, -0.02, 0.5 * kDeg};
  f.Shift(correction);
  for (size_t i = 0; i < before.size(); ++i) {
    const Pose2D want = correction.Compose(before[i].pose);
    EXPECT_NEAR(f.particles()[i].pose.x, want.x, 1e-12);
    EXPECT_NEAR(f.particles()[i].pose.y, want.y, 1e-12);
    EXPECT_NEAR(f.particles()[i].pose.theta, want.theta, 1e-12);
  }
  const Pose2D want = correction.Compose(estimate);
  EXPECT_NEAR(f.status().pose.x, want.x, 1e-12);
  EXPECT_NEAR(f.status().pose.theta, want.theta, 1e-12);
}

}  // namespace
}  // namespace mbot::mapping
