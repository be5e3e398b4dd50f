// The SLAM pieces on tiny fixtures: Bresenham ends, odds saturation, resampling, action-model
// statistics, the sensor model's preference for the true pose, thread-count independence and ATE.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "mbot/mapping/action_model.hpp"
#include "mbot/mapping/log_odds_mapper.hpp"
#include "mbot/mapping/particle_filter.hpp"
#include "mbot/mapping/sensor_model.hpp"
#include "mbot/motion/trajectory_error.hpp"
#include "room_fixture.hpp"

namespace mbot::mapping {
namespace {

using motion::Pose2D;

TEST(Bresenham, IncludesBothEndsInOrder) {
  std::vector<int> xs, ys;
  BresenhamLine(0, 0, 5, -3, &xs, &ys);
  ASSERT_GE(xs.size(), 6u);
  EXPECT_EQ(xs.front(), 0);
  EXPECT_EQ(ys.front(), 0);
  EXPECT_EQ(xs.back(), 5);
  EXPECT_EQ(ys.back(), -3);
  for (size_t i = 1; i < xs.size(); ++i) {  // 8-connected steps
    EXPECT_LE(std::abs(xs[i] - xs[i - 1]), 1);
    EXPECT_LE(std::abs(ys[i] - ys[i - 1]), 1);
  }
}

TEST(LogOddsMapper, HitsSaturateAt127AndMissesAtMinus127) {
  MapperOptions o;
  o.hit_odds = 50;
  o.miss_odds = 40;
  o.width_m = o.height_m = 2.0;
  LogOddsMapper m(o);
  const std::vector<ScanRay> rays = {ScanRay{0, 0, 0.52f, 0, true}};
  for (int i = 0; i < 10; ++i) m.Insert(rays, Pose2D{});
  int cx, cy;
  m.map().WorldToCell(0.52, 0.0, &cx, &cy);
  EXPECT_EQ(m.map().at(cx, cy), 127);
  m.map().WorldToCell(0.26, 0.0, &cx, &cy);
  EXPECT_EQ(m.map().at(cx, cy), -127);
}

TEST(LogOddsMapper, MissRaysClearButMarkNothingAndTheMapGrows) {
  MapperOptions o;
  o.width_m = o.height_m = 1.0;
  LogOddsMapper m(o);
  m.Insert({ScanRay{0, 0, 2.0f, 0, false}}, Pose2D{});
  EXPECT_GE(m.grow_count(), 1);
  EXPECT_EQ(m.map().CountCells().occupied, 0);
  int cx, cy;
  m.map().WorldToCell(1.9, 0.0, &cx, &cy);
  ASSERT_TRUE(m.map().IsInside(cx, cy));
  EXPECT_LT(m.map().at(cx, cy), 0);
}

TEST(ActionModel, SampleSpreadMatchesK1K2) {
  ActionModelOptions o;
  o.k1 = 0.01;
  o.k2 = 0.02;
  o.min_sigma_rot_rad = o.min_sigma_trans_m = 0;
  ActionModel a(o);
  const OdometryStep step = ActionModel::StepBetween(Pose2D{}, Pose2D{1.0, 0.0, 0.0});
  EXPECT_NEAR(step.trans, 1.0, 1e-12);
  double sum = 0, sq = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const Pose2D p = a.Sample(Pose2D{}, step, 1000 + i);
    sum += p.x;
    sq += p.x * p.x;
  }
  const double mean = sum / n, sd = std::sqrt(sq / n - mean * mean);
  EXPECT_NEAR(mean, 1.0, 0.005);
  EXPECT_NEAR(sd, std::sqrt(0.02 * 1.0), 0.1 * std::sqrt(0.02));  // σ_trans = sqrt(k2·|trans|) within 10 %
}

TEST(ActionModel, BackwardStepKeepsSmallRotations) {
  const OdometryStep s = ActionModel::StepBetween(Pose2D{}, Pose2D{-0.5, 0.0, 0.0});
  EXPECT_NEAR(s.trans, -0.5, 1e-12);
  EXPECT_NEAR(s.rot1, 0.0, 1e-12);
  EXPECT_NEAR(s.rot2, 0.0, 1e-12);
}

TEST(SensorModel, LikelihoodFieldPrefersTheTruePose) {
  Room room;
  for (auto kind : {SensorModelKind::kLikelihoodField, SensorModelKind::kSimplifiedField}) {
    SensorModelOptions o;
    o.kind = kind;
    SensorModel sm(o);
    sm.SetMap(room.map);
    const ScanPoints pts = sm.Prepare(room.rays);
    const double best = sm.LogLikelihood(room.truth, pts);
    for (const Pose2D& off : {Pose2D{0.1, 0, 0}, Pose2D{0, -0.1, 0}, Pose2D{0, 0, 0.1}}) {
      const Pose2D wrong{room.truth.x + off.x, room.truth.y + off.y, room.truth.theta + off.theta};
      EXPECT_GT(best, sm.LogLikelihood(wrong, pts)) << int(kind);
    }
    EXPECT_GT(sm.InlierFraction(room.truth, pts), 0.95);
    EXPECT_LT(sm.InlierFraction(Pose2D{-1.0, -1.0, 2.0}, pts), 0.6);
  }
}

TEST(SensorModel, UpdatingAMapGivesTheSameTablesAsBuildingItAfresh) {
  for (auto kind : {SensorModelKind::kLikelihoodField, SensorModelKind::kSimplifiedField}) {
    Room room;
    SensorModelOptions o;
    o.kind = kind;
    SensorModel updated(o);
    updated.SetMap(room.map);
    updated.SetMap(room.map);  // nothing changed
    // An obstacle appears inside, one wall cell vanishes, a free cell gets less free.
    room.map.at(40, 40) = 90;
    room.map.at(0, 10) = -20;
    room.map.at(60, 20) = -5;
    updated.SetMap(room.map);
    SensorModel fresh(o);
    fresh.SetMap(room.map);
    ScanPoints one;
    one.x = {0}, one.y = {0}, one.step_x = {0.05f}, one.step_y = {0};
    for (int cy = -1; cy <= 80; ++cy) {
      for (int cx = -1; cx <= 80; ++cx) {
        double x, y;
        room.map.CellToWorld(cx, cy, &x, &y);
        const Pose2D at{x, y, 0};
        ASSERT_EQ(updated.LogLikelihood(at, one), fresh.LogLikelihood(at, one))
            << cx << "," << cy << " kind " << int(kind);
        ASSERT_EQ(updated.InlierFraction(at, one), fresh.InlierFraction(at, one)) << cx << "," << cy;
      }
    }
  }
}

// The eight-lane sums equal the beams' own values added up (each weighed alone, as a one-beam
// scan), and the AVX2 weighing gives the same sums as the scalar one to the last bit, on and off
// the map, for scans whose length is and is not a multiple of the eight lanes. (Without AVX2 both
// models run the scalar path: the first check still bites.)
TEST(SensorModel, SimdAndScalarSumsAreIdentical) {
  Room room;
  SensorModelOptions o;
  SensorModel simd(o);
  o.simd = false;
  SensorModel scalar(o);
  simd.SetMap(room.map);
  scalar.SetMap(room.map);
  ScanPoints pts = simd.Prepare(room.rays);
  ASSERT_GE(pts.size(), 20u);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> pos(-2.0, 6.0), ang(-4.0, 4.0);
  int compared = 0;
  for (int trim = 0; trim < 8; ++trim) {
    for (int k = 0; k < 5000; ++k) {
      const Pose2D p{pos(rng), pos(rng), ang(rng)};  // some poses put beams off the map
      const double sum = scalar.LogLikelihood(p, pts);
      ASSERT_EQ(simd.LogLikelihood(p, pts), sum) << "pose " << k << " beams " << pts.size();
      if (k % 50 == 0) {
        double beams = 0.0;
        ScanPoints one;
        one.x.resize(1), one.y.resize(1), one.step_x.resize(1), one.step_y.resize(1);
        for (size_t i = 0; i < pts.size(); ++i) {
          one.x[0] = pts.x[i], one.y[0] = pts.y[i], one.step_x[0] = pts.step_x[i], one.step_y[0] = pts.step_y[i];
          beams += scalar.LogLikelihood(p, one);
        }
        ASSERT_NEAR(sum, beams, 1e-5 * std::abs(beams) + 1e-5) << "pose " << k << " beams " << pts.size();
      }
      ++compared;
    }
    pts.x.pop_back(), pts.y.pop_back(), pts.step_x.pop_back(), pts.step_y.pop_back();
  }
  EXPECT_EQ(compared, 40000);
}

TEST(SensorModel, WithoutAMapEveryPoseWeighsTheSame) {  // action-only mode
  Room room;
  SensorModel sm(SensorModelOptions{});
  const ScanPoints pts = sm.Prepare(room.rays);
  EXPECT_EQ(sm.LogLikelihood(room.truth, pts), 0.0);
  EXPECT_EQ(sm.LogLikelihood(Pose2D{-1, 2, 3}, pts), 0.0);
}

TEST(ParticleFilter, SameResultForAnyThreadCountAndResamplingKeepsTheMean) {
  Room room;
  SensorModel sm(SensorModelOptions{});
  sm.SetMap(room.map);
  const ScanPoints pts = sm.Prepare(room.rays);
  ActionModel am(ActionModelOptions{});
  std::vector<std::vector<Particle>> results;
  for (int threads : {1, 2}) {
    ParticleFilterOptions o;
    o.particles = 2000;
    o.threads = threads;
    ParticleFilter pf(o, 42);
    pf.InitializeAt(Pose2D{0.95, 0.55, 0.25}, 0.05, 0.05);
    for (int k = 0; k < 5; ++k) pf.Update(am, OdometryStep{}, sm, pts);
    results.push_back(pf.particles());
    EXPECT_NEAR(pf.status().pose.x, room.truth.x, 0.03);
    EXPECT_NEAR(pf.status().pose.y, room.truth.y, 0.03);
    EXPECT_NEAR(pf.status().pose.theta, room.truth.theta, 0.03);
    EXPECT_GT(pf.status().ess, 1.0);
  }
  ASSERT_EQ(results[0].size(), results[1].size());
  for (size_t i = 0; i < results[0].size(); ++i) {
    EXPECT_EQ(results[0][i].pose.x, results[1][i].pose.x);
    EXPECT_EQ(results[0][i].weight, results[1][i].weight);
  }
}

TEST(ParticleFilter, GlobalLocalizationFindsTheRobotInTheRoom) {
  Room room;
  // Break the room's symmetry: wall off one quadrant, making it L-shaped.
  for (int x = 40; x < 80; ++x)
    for (int y = 0; y < 30; ++y) room.map.at(x, y) = 100;
  const std::vector<ScanRay> rays = MarchScan(room.map, room.truth);
  SensorModelOptions so;
  so.log_scale = 0.2;
  SensorModel sm(so);
  sm.SetMap(room.map);
  const ScanPoints pts = sm.Prepare(rays);
  ActionModel am(ActionModelOptions{});
  ParticleFilterOptions o;
  o.global_particles = 50000;
  ParticleFilter pf(o, 7);
  pf.SetFreeSpace(room.map);
  pf.InitializeGlobal();
  for (int k = 0; k < 10; ++k) pf.Update(am, OdometryStep{}, sm, pts);
  EXPECT_TRUE(pf.status().converged);
  EXPECT_NEAR(pf.status().pose.x, room.truth.x, 0.1);
  EXPECT_NEAR(pf.status().pose.y, room.truth.y, 0.1);
}

TEST(ParticleFilter, GlobalRegionLimitsTheFirstSpread) {
  Room room;
  ParticleFilterOptions o;
  o.global_particles = 5000;
  o.global_region = SearchBox{0.2, 0.8, 0.3, 0.6};
  ParticleFilter pf(o, 3);
  pf.SetFreeSpace(room.map);
  pf.InitializeGlobal();
  ASSERT_EQ(pf.particles().size(), 5000u);
  for (const Particle& p : pf.particles()) {
    ASSERT_GE(p.pose.x, 0.2 - room.map.resolution());
    ASSERT_LE(p.pose.x, 0.8 + room.map.resolution());
    ASSERT_GE(p.pose.y, 0.3 - room.map.resolution());
    ASSERT_LE(p.pose.y, 0.6 + room.map.resolution());
  }
  o.global_region = SearchBox{50, 60, 50, 60};  // off the map
  ParticleFilter off(o, 3);
  off.SetFreeSpace(room.map);
  EXPECT_THROW(off.InitializeGlobal(), std::runtime_error);
}

TEST(ParticleFilter, GlobalSearchTempersTheLikelihoodToKeepParticlesEffective) {
  Room room;
  const std::vector<ScanRay> rays = MarchScan(room.map, room.truth);
  SensorModel sm(SensorModelOptions{});  // untempered: one scan is far too peaked for 20k spread particles
  sm.SetMap(room.map);
  const ScanPoints pts = sm.Prepare(rays);
  ActionModel am(ActionModelOptions{});
  for (double fraction : {0.0, 0.05}) {
    ParticleFilterOptions o;
    o.global_particles = 20000;
    o.global_min_ess_fraction = fraction;
    ParticleFilter pf(o, 11);
    pf.SetFreeSpace(room.map);
    pf.InitializeGlobal();
    const FilterStatus s = pf.Update(am, OdometryStep{}, sm, pts);
    if (fraction == 0.0) {
      EXPECT_EQ(s.tempering, 1.0);
      EXPECT_LT(s.ess, 0.05 * 20000);
    } else {
      EXPECT_LT(s.tempering, 1.0);
      EXPECT_NEAR(s.ess, 0.05 * 20000, 0.05 * 20000 * 0.01);  // the largest exponent that keeps the target
    }
  }
}

TEST(TrajectoryError, AlignmentRemovesAKnownRigidTransform) {
  std::vector<Pose2D> truth, est;
  const Pose2D t{0.3, -0.2, 0.4};
  for (int i = 0; i < 50; ++i) {
    const Pose2D p{std::cos(i * 0.1), std::sin(i * 0.2), i * 0.05};
    truth.push_back(p);
    est.push_back(t.Inverse().Compose(p));
  }
  const auto a = motion::ComputeAte(est, truth, motion::AteAlignment::kBestFitSE2);
  EXPECT_LT(a.xy.rmse, 1e-9);
  EXPECT_LT(a.theta.rmse, 1e-9);
  EXPECT_NEAR(a.alignment.theta, 0.4, 1e-9);
  const auto u = motion::ComputeAte(est, truth, motion::AteAlignment::kNone);
  EXPECT_GT(u.xy.rmse, 0.1);
}

// The streamed (two-pass, raw-moment) alignment against the textbook one — centred sums — written
// out here, on a noisy path 2 km from the origin (hours of soak or a UTM frame).
TEST(TrajectoryError, StreamedAlignmentEqualsTheCentredTwoPassFit) {
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0, 0.02);
  std::vector<Pose2D> truth, est;
  const Pose2D t{1.3, -0.7, 0.25};
  for (int i = 0; i < 5000; ++i) {
    const Pose2D p{2000 + 10 * std::cos(i * 0.003), -1500 + 6 * std::sin(i * 0.005), i * 0.01};
    truth.push_back(p);
    est.push_back(t.Inverse().Compose(Pose2D{p.x + noise(rng), p.y + noise(rng), p.theta + noise(rng)}));
  }
  double ex = 0, ey = 0, tx = 0, ty = 0;
  for (size_t i = 0; i < est.size(); ++i) ex += est[i].x, ey += est[i].y, tx += truth[i].x, ty += truth[i].y;
  ex /= est.size(), ey /= est.size(), tx /= est.size(), ty /= est.size();
  double sxx = 0, sxy = 0;
  for (size_t i = 0; i < est.size(); ++i) {
    const double ax = est[i].x - ex, ay = est[i].y - ey, bx = truth[i].x - tx, by = truth[i].y - ty;
    sxx += ax * bx + ay * by, sxy += ax * by - ay * bx;
  }
  const double theta = std::atan2(sxy, sxx);
  const Pose2D want{tx - (std::cos(theta) * ex - std::sin(theta) * ey),
                    ty - (std::sin(theta) * ex + std::cos(theta) * ey), theta};
  motion::AteAccumulator acc(motion::AteAlignment::kBestFitSE2);
  for (size_t i = 0; i < est.size(); ++i) acc.AddForAlignment(est[i], truth[i]);
  for (size_t i = 0; i < est.size(); ++i) acc.AddError(est[i], truth[i]);
  const motion::AteResult r = acc.Result();
  EXPECT_NEAR(r.alignment.x, want.x, 1e-6);
  EXPECT_NEAR(r.alignment.y, want.y, 1e-6);
  EXPECT_NEAR(r.alignment.theta, want.theta, 1e-10);
  EXPECT_NEAR(r.alignment.theta, 0.25, 0.01);
  double sq = 0;
  for (size_t i = 0; i < est.size(); ++i) {
    const Pose2D a = want.Compose(est[i]);
    sq += (a.x - truth[i].x) * (a.x - truth[i].x) + (a.y - truth[i].y) * (a.y - truth[i].y);
  }
  EXPECT_NEAR(r.xy.rmse, std::sqrt(sq / est.size()), 1e-9);
  EXPECT_EQ(r.samples, 5000);
  EXPECT_THROW(motion::AteAccumulator(motion::AteAlignment::kFirstPose).Result(), std::invalid_argument);
}

}  // namespace
}  // namespace mbot::mapping
