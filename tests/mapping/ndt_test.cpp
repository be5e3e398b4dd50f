// The normal-distributions transform over a log-odds map's hit moments (ndt.hpp) on the room
// fixture, whose walls' surfaces lie on cell borders: with 2.2 cm of range noise (the MBot's lidar)
// a wall's hits fill the two cells either side of its surface, a band over which a likelihood field
// of whole cells is flat, while the hits' Gaussians still place the scan to millimetres.
#include "mbot/mapping/ndt.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "mbot/mapping/log_odds_mapper.hpp"
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
  ASSERT_GT(mapper.grow_count(), 0);
  double hits = 0;
  for (int y = 0; y < mapper.moments().height(); ++y)
    for (int x = 0; x < mapper.moments().width(); ++x)
      for (int k = 0; k < HitMoments::kDirections; ++k) hits += mapper.moments().at(x, y, k).n;
  EXPECT_EQ(hits, 20 * 360);

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
  // With no hit moments (a map given whole), nothing moves.
  const HitMoments none;
  EXPECT_EQ(RefineNdt(mapper.map(), none, points, truth, o).points_used, 0);
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
    o.refine.occupied_threshold = 30;
    Slam slam(o, 3);
    std::mt19937 rng(11);
    Pose2D truth{-0.5, -0.5, 0}, odometry = truth;
    slam.Initialize(truth, odometry);
    for (int i = 0; i < 10; ++i) slam.ProcessScan(NoisyScan(room, truth, 0.022, &rng), odometry);  // standing
    double worst = 0;
    for (int i = 1; i <= 40; ++i) {
      truth = truth.Compose(Pose2D{0.05, 0.0, (i <= 20 ? 2.0 : -2.0) * kDeg});
      odometry = odometry.Compose(Pose2D{0.05, 0.0, (i <= 20 ? 2.3 : -1.7) * kDeg});
      const SlamStep step = slam.ProcessScan(NoisyScan(room, truth, 0.022, &rng), odometry);
      worst = std::max(worst, std::abs(motion::WrapAngle(step.pose.theta - truth.theta)));
    }
    return worst / kDeg;
  };
  const double refined = run(true), filter_alone = run(false);
  EXPECT_LT(refined, 0.3) << "the filter alone: " << filter_alone << " deg";
}

}  // namespace
}  // namespace mbot::mapping
