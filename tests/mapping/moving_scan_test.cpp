// Beam timing (mapping::TimeBeams) and the SLAM event tracker, on tiny inputs.
#include "mbot/mapping/moving_scan.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "mbot/mapping/scan_perturbation.hpp"
#include "mbot/mapping/slam.hpp"

namespace mbot::mapping {
namespace {

std::vector<float> Revolution(int n) {
  std::vector<float> a(n);
  for (int i = 0; i < n; ++i) a[i] = static_cast<float>(2 * M_PI * i / n);
  return a;
}

TEST(TimeBeams, UsesTheBeamsOwnTimesWhenTheySpanTheScan) {
  const std::vector<float> angles = Revolution(5);
  const std::vector<int64_t> times = {1000, 26000, 51000, 76000, 101000};
  const BeamTimes b = TimeBeams(BeamTiming::kAuto, angles, times, 125000);
  EXPECT_EQ(b.duration_us, 100000);
  ASSERT_EQ(b.fractions.size(), 5u);
  EXPECT_FLOAT_EQ(b.fractions[0], 0.0f);
  EXPECT_FLOAT_EQ(b.fractions[2], 0.5f);
  EXPECT_FLOAT_EQ(b.fractions[4], 1.0f);
}

TEST(TimeBeams, SpreadsARevolutionWithoutBeamTimesOverThePeriod) {
  const BeamTimes b = TimeBeams(BeamTiming::kAuto, Revolution(8), {}, 125000);
  EXPECT_EQ(b.duration_us, 125000);
  ASSERT_EQ(b.fractions.size(), 8u);
  EXPECT_FLOAT_EQ(b.fractions[7], 1.0f);
  // A partial sweep (not a turn) or an unknown period: no deskew.
  EXPECT_TRUE(TimeBeams(BeamTiming::kAuto, {0.0f, 0.1f, 0.2f}, {}, 125000).fractions.empty());
  EXPECT_TRUE(TimeBeams(BeamTiming::kAuto, Revolution(8), {}, 0).fractions.empty());
  EXPECT_TRUE(TimeBeams(BeamTiming::kNone, Revolution(8), {}, 125000).fractions.empty());
}

TEST(TimeBeams, AskedForBeamTimesThatDoNotSpanTheScanSaysSo) {
  const BeamTimes b = TimeBeams(BeamTiming::kBeams, Revolution(3), {0, 1, 2}, 125000);
  EXPECT_TRUE(b.beam_times_unusable);
  EXPECT_TRUE(b.fractions.empty());
}

TEST(SlamEventTracker, ConvergenceLostAndRecovered) {
  SlamEventTracker t(0.6);
  t.GlobalStarted();
  FilterStatus s;
  s.converged = false;
  EXPECT_EQ(t.Add(0.1, 0, true, s), "");
  s.converged = true;
  s.inlier_fraction = 0.9;
  EXPECT_NE(t.Add(0.2, 1, true, s).find("converged after 2 scans"), std::string::npos);
  s.lost = true;
  s.inlier_fraction = 0.2;
  EXPECT_NE(t.Add(5.0, 40, true, s).find("lost at 5 s"), std::string::npos);
  EXPECT_EQ(t.Add(5.1, 41, true, s), "");  // still lost: one episode
  s.lost = false;
  s.inlier_fraction = 0.5;  // converged, but the scan does not fit yet
  EXPECT_EQ(t.Add(5.2, 42, true, s), "");
  s.inlier_fraction = 0.8;
  EXPECT_NE(t.Add(5.3, 43, true, s).find("recovered"), std::string::npos);
  EXPECT_DOUBLE_EQ(t.converged_at_s(), 0.2);
  ASSERT_EQ(t.lost().size(), 1u);
  EXPECT_EQ(t.lost()[0].recovered_at_scan - t.lost()[0].at_scan, 3);
}

}  // namespace
}  // namespace mbot::mapping

namespace mbot::mapping {
namespace {

// A robot turning on the spot at 1 rad per scan: each beam is rotated by the turn left to go
// after it was measured, so the rays come out in the frame of the pose at the scan's end.
TEST(DeskewScan, RaysLandInTheFrameOfTheScansEnd) {
  const std::vector<float> ranges = {1.0f, 1.0f, 1.0f};
  const std::vector<float> angles = {0.0f, 0.0f, 0.0f};
  const std::vector<float> fractions = {0.0f, 0.5f, 1.0f};
  const motion::Pose2D start_in_end{0, 0, -1.0};  // the robot turned +1 rad during the scan
  ScanOptions o;
  const std::vector<ScanRay> rays = DeskewScan(ranges, angles, fractions, start_in_end, {}, 0.0, o);
  ASSERT_EQ(rays.size(), 3u);
  EXPECT_NEAR(std::atan2(rays[0].ey, rays[0].ex), -1.0, 1e-5);
  EXPECT_NEAR(std::atan2(rays[1].ey, rays[1].ex), -0.5, 1e-5);
  EXPECT_NEAR(std::atan2(rays[2].ey, rays[2].ex), 0.0, 1e-5);
  for (const ScanRay& r : rays) EXPECT_NEAR(std::hypot(r.ex - r.ox, r.ey - r.oy), 1.0, 1e-5);
}

TEST(DeskewScan, ShortAndMissingReturnsClearNothingOrAreMisses) {
  ScanOptions o;
  o.min_range_m = 0.1;
  o.max_range_m = 5.0;
  const std::vector<ScanRay> rays = DeskewScan({0.05f, 6.0f, 2.0f, -1.0f}, {0, 0, 0, 0}, {}, {}, {}, 0.0, o);
  int hits = 0, misses = 0;
  for (const ScanRay& r : rays) (r.hit ? hits : misses)++;
  EXPECT_EQ(hits, 1);    // 2.0 m
  EXPECT_LE(misses, 1);  // 6.0 m beyond max_range_m clears as a miss; too short and no return are dropped
}

// A return at the sensor's own maximum is no return (glass, the open), not a measured distance:
// it clears only no_return_clear_m. A return beyond our cap but short of the sensor's maximum was
// measured, and clears up to the cap.
TEST(DeskewScan, TheSensorsMaximumIsNoReturn) {
  ScanOptions o;
  o.max_range_m = 30.0;
  std::vector<ScanRay> rays = DeskewScan({81.0f, 40.0f}, {0, 0}, {}, {}, {}, 81.0, o);
  ASSERT_EQ(rays.size(), 1u);  // 81 m dropped; 40 m clears 30 m
  EXPECT_FALSE(rays[0].hit);
  EXPECT_NEAR(rays[0].ex, 30.0f, 1e-4);
  o.no_return_clear_m = 2.0;
  rays = DeskewScan({81.0f}, {0}, {}, {}, {}, 81.0, o);
  ASSERT_EQ(rays.size(), 1u);
  EXPECT_FALSE(rays[0].hit);
  EXPECT_NEAR(rays[0].ex, 2.0f, 1e-4);
}

// Glass: with every wall patch glass, every return goes through (no return at the sensor's maximum,
// or a return 1.5-3 times as far), about half each way; with none, nothing changes.
TEST(ScanPerturbation, GlassSendsReturnsThroughOrBeyond) {
  const std::vector<float> angles = Revolution(360);
  std::vector<float> ranges(360, 2.0f);
  ScanPerturbationOptions o;
  o.glass_share = 1.0;
  ScanPerturbation glass(o, 7);
  glass.Apply(1'000'000, {}, angles, 10.0, &ranges);
  int through = 0, beyond = 0;
  for (float r : ranges) {
    if (r == 10.0f) {
      ++through;
    } else {
      ++beyond;
      EXPECT_GE(r, 3.0f);
      EXPECT_LE(r, 6.0f);
    }
  }
  EXPECT_EQ(glass.glass_beams(), 360);
  EXPECT_GT(through, 120);
  EXPECT_GT(beyond, 120);
  std::vector<float> clear(360, 2.0f);
  o.glass_share = 0.0;
  o.people = 0;
  ScanPerturbation none(o, 7);
  EXPECT_FALSE(o.any());
  none.Apply(1'000'000, {}, angles, 10.0, &clear);
  EXPECT_EQ(clear, std::vector<float>(360, 2.0f));
}

// People: inside a 5 m ring of wall, a person 0.8-4 m away hides a few degrees of it at their
// distance (under 5 m), moves at walking speed between scans, and the same seed draws the same
// people.
TEST(ScanPerturbation, PeopleHideTheWallAndWalk) {
  const std::vector<float> angles = Revolution(720);
  ScanPerturbationOptions o;
  o.people = 1;
  ScanPerturbation a(o, 3), b(o, 3);
  auto hidden = [&](ScanPerturbation& p, int64_t t_us, std::vector<float>* ranges) {
    ranges->assign(720, 5.0f);
    p.Apply(t_us, {}, angles, 10.0, ranges);
    std::vector<int> beams;
    for (int i = 0; i < 720; ++i) {
      if ((*ranges)[i] < 5.0f) {
        EXPECT_GE((*ranges)[i], 0.6f);
        EXPECT_LE((*ranges)[i], 4.0f);
        beams.push_back(i);
      }
    }
    return beams;
  };
  std::vector<float> r1, r2, r3;
  const std::vector<int> first = hidden(a, 0, &r1);
  ASSERT_GE(first.size(), 5u);   // 0.4 m wide at <= 4 m: >= 5.7 degrees, 11 beams of 0.5
  ASSERT_LE(first.size(), 60u);  // at >= 0.8 m: <= 29 degrees
  EXPECT_EQ(hidden(b, 0, &r2), first);
  EXPECT_EQ(r1, r2);
  // 0.2 s later the person has walked 0.2 m: the nearest range or the hidden beams changed.
  const std::vector<int> later = hidden(a, 200'000, &r3);
  ASSERT_FALSE(later.empty());
  EXPECT_TRUE(later != first || r3 != r1);
  EXPECT_EQ(a.person_beams(), static_cast<long long>(first.size() + later.size()));
}

// Range smoothing: along a wall 1 m ahead measured with ±2 cm of alternating noise, each return
// becomes the mean of itself and its two neighbours (the noise falls to a third); at a step to a
// wall 0.5 m behind, each side keeps its own range; a lost beam stays lost.
TEST(DeskewScan, SmoothingAveragesASurfaceAndKeepsItsEdges) {
  std::vector<float> ranges, angles;
  for (int i = 0; i < 20; ++i) {
    ranges.push_back((i < 10 ? 1.0f : 1.5f) + (i % 2 == 0 ? 0.02f : -0.02f));
    angles.push_back(0.0f);
  }
  ranges[15] = NAN;
  ScanOptions o;
  o.smooth_beams = 1;
  const std::vector<ScanRay> rays = DeskewScan(ranges, angles, {}, {}, {}, 0.0, o);
  ASSERT_EQ(rays.size(), 19u);  // the lost beam is dropped, as without smoothing
  for (size_t i = 1; i + 1 < rays.size(); ++i) {
    const double r = rays[i].ex, expect = i < 10 ? 1.0 : 1.5;
    if (i == 14 || i == 15) continue;     // next to the lost beam: one neighbour only
    EXPECT_NEAR(r, expect, 0.0068) << i;  // (2 - 1) × 2 cm / 3 at most
  }
  // Either side of the edge: itself and its one neighbour on the same wall.
  EXPECT_NEAR(rays[9].ex, (0.98 + 1.02) / 2, 1e-6);
  EXPECT_NEAR(rays[10].ex, (1.52 + 1.48) / 2, 1e-6);
  o.smooth_beams = 0;
  EXPECT_NEAR(DeskewScan(ranges, angles, {}, {}, {}, 0.0, o)[1].ex, 0.98, 1e-6);
}

}  // namespace
}  // namespace mbot::mapping
