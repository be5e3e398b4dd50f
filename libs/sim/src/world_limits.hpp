// The limits the arena parser and the world builders share, and their number formatting.
#pragma once

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>

namespace mbot::sim::world_limits {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = 3.14159265358979323846;
// Ranges accepted for an arena's true-map resolution and wall thickness [m].
constexpr double kMinResolution = 0.005, kMaxResolution = 0.5;
constexpr double kMinThickness = 0.001, kMaxThickness = 1.0;
// Free cells kept around the walls' (thickened) bounding box in the true map.
constexpr int kMarginCells = 4;
// Largest true map side [cells]: a typo in a coordinate should fail, not allocate gigabytes.
constexpr double kMaxCellsPerSide = 20000;
// Largest true map [cells]: 64 Mi cells (a 80 x 80 m arena at 1 cm) take about 0.3 GB with the
// distance transform's 4 bytes a cell; 0.005 m over a 100 m box would be 1.5 GB.
constexpr double kMaxWorldCells = 64.0 * 1024 * 1024;
// Walls in one arena (each is rasterised along its length, so loading grows with their total length).
constexpr size_t kMaxWalls = 100000;
// Bucket side of the arena acceleration grid [m]. On maze_3 (16 walls, mean ray 0.7 m), 0.45–1.0 m
// buckets all cast about 4.5–5 M rays/s, 0.15 m ones 2.9 M, one bucket for everything 2.6 M.
constexpr double kBucketSize = 0.5;

inline std::string Num(double v) {
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

// A wall as the ray caster sees it: start point, unit direction and length.
struct Capsule {
  double ax, ay, ux, uy, len;
};

// Distance along the unit ray (ox, oy) + s (dx, dy) to the surface of the capsule of radius h
// around the segment; 0 when the origin is inside (or on) it; +inf when the ray misses.
inline double RayCapsule(const Capsule& c, double h, double ox, double oy, double dx, double dy) {
  const double wx = ox - c.ax, wy = oy - c.ay;
  const double ou = wx * c.ux + wy * c.uy;   // along the segment
  const double ov = -wx * c.uy + wy * c.ux;  // across it
  const double eu = ou - std::clamp(ou, 0.0, c.len);
  if (eu * eu + ov * ov <= h * h) return 0.0;
  const double du = dx * c.ux + dy * c.uy;
  const double dv = -dx * c.uy + dy * c.ux;
  const double aov = std::abs(ov);
  if (aov > h && ov * dv < 0.0) {
    // Entering the slab |v| <= h: everything before is outside the capsule, so a side-face hit
    // within the segment's length is the first entry.
    const double s = (aov - h) / std::abs(dv);
    const double u = ou + s * du;
    if (u >= 0.0 && u <= c.len) return s;
  }
  // Otherwise the ray can only enter through an end disc (the origin is outside both).
  double best = kInf;
  for (const double cu : {0.0, c.len}) {
    const double pu = ou - cu;
    const double b = pu * du + ov * dv;
    if (b >= 0.0) continue;  // moving away from this end
    const double disc = b * b - (pu * pu + ov * ov - h * h);
    if (disc < 0.0) continue;
    best = std::min(best, -b - std::sqrt(disc));
  }
  return best;
}

// Squared distance from (px, py) to the capsule's centre segment.
inline double SegmentDist2(const Capsule& c, double px, double py) {
  const double wx = px - c.ax, wy = py - c.ay;
  const double ou = wx * c.ux + wy * c.uy;
  const double ov = -wx * c.uy + wy * c.ux;
  const double eu = ou - std::clamp(ou, 0.0, c.len);
  return eu * eu + ov * ov;
}

// The stretch of the horizontal line at `y` within `r` of the capsule's centre segment, as a
// superset [x_lo, x_hi]; false when the line is farther than `r` from the segment.
inline bool RowSpan(const Capsule& c, double y, double r, double* x_lo, double* x_hi) {
  double s0 = 0.0, s1 = c.len;
  if (std::abs(c.uy) < 1e-12) {
    if (std::abs(y - c.ay) > r) return false;
  } else {
    const double sa = (y - r - c.ay) / c.uy, sb = (y + r - c.ay) / c.uy;
    s0 = std::max(s0, std::min(sa, sb));
    s1 = std::min(s1, std::max(sa, sb));
    if (s0 > s1) return false;
  }
  const double xa = c.ax + c.ux * s0, xb = c.ax + c.ux * s1;
  *x_lo = std::min(xa, xb) - r;
  *x_hi = std::max(xa, xb) + r;
  return true;
}

}  // namespace mbot::sim::world_limits
