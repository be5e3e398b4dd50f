// Occupancy-grid file formats: botlab `.map`, ROS map_server PGM + YAML, MRPT `.gridmap(.gz)`,
// MRPT `.simplemap(.gz)` (rendered to a grid), Moving AI `.map`, and PNG pictures. Readers throw std::runtime_error
// naming the file (and line).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mbot/msgs/occupancy_grid.hpp"
#include "mbot/msgs/pose2d.hpp"

namespace mbot::drivers {

// botlab: "origin_x origin_y width height meters_per_cell", then `height` rows of `width` int8
// log-odds, row y = 0 first. Lossless round trip.
// What a map file's header may ask for: at most kMaxMapCells cells (a 16,384 × 16,384 grid, 256 MB
// of int8), no more cells than the file's bytes can hold (a text map spends at least one byte per
// cell, a binary PGM exactly one), origins within ±1e6 m and a resolution in [1e-4, 100] m. A header
// beyond them is an error naming the file, the field and the value, before anything is allocated.
inline constexpr long long kMaxMapCells = msgs::kMaxGridCells;

msgs::OccupancyGrid ReadBotlabMap(const std::string& path);
void WriteBotlabMap(const msgs::OccupancyGrid& grid, const std::string& path);

// ROS map_server: YAML (image, resolution, origin [x, y, yaw], negate, occupied_thresh,
// free_thresh, mode) + image, top image row = highest y. Cells are classified with the thresholds
// as map_server does; occupied and free cells keep a graded log-odds from the pixel value.
// Written maps use pixel = 127 - log-odds with thresholds that split at log-odds 0, so a
// botlab grid survives the round trip exactly.
// `saver_unknown`: a trinary map's pixel 205 (negate 0, as map_saver writes) is unknown whatever the thresholds say.
// nav2's map_saver writes never-mapped cells as 205 with free_thresh 0.25, which map_server's own
// rule ((255 - 205) / 255 = 0.196 < 0.25) reads back as free: floor nobody saw.
msgs::OccupancyGrid ReadRosMap(const std::string& yaml_path, bool saver_unknown = false);
void WriteRosMap(const msgs::OccupancyGrid& grid, const std::string& yaml_path);

// MRPT COccupancyGridMap2D serialised with CArchive (optionally gzip-compressed). MRPT cells hold
// the probability of being free; it becomes log-odds of occupancy scaled by 20 and clamped.
msgs::OccupancyGrid ReadMrptGridmap(const std::string& path);

// MRPT CSimpleMap (keyframe poses, each with its sensory frame): every 2D range scan is inserted
// at its keyframe's mean pose with the project's own log-odds mapper (default MapperOptions at
// `resolution_m`, growing to fit), so the grid has the same log-odds semantics as one we map.
msgs::OccupancyGrid ReadMrptSimplemap(const std::string& path, double resolution_m = 0.05);

// Moving AI benchmark map ("type octile", height, width, "map", rows; (0,0) top-left). Passable
// terrain ('.', 'G', 'S') becomes free (-127), everything else occupied (127); 1 m cells, with
// Moving AI row r stored as grid row height-1-r.
msgs::OccupancyGrid ReadMovingAiMap(const std::string& path);

// A picture for people: occupied dark, free light, unknown grey, graded by log-odds; top = +y.
void WriteMapPng(const msgs::OccupancyGrid& grid, const std::string& path);

// Something drawn over a map picture: a path (a polyline through the poses) or a set of points.
struct MapOverlay {
  std::vector<msgs::Pose2D> poses;
  uint8_t r = 0, g = 0, b = 0;
  bool points = false;      // dots instead of a polyline
  std::string label;        // shown in the legend when non-empty
  int point_radius_px = 1;  // points: a dot of this radius, or a ring above 2 pixels
};

// The map picture in colour, `scale` pixels per cell, with the overlays drawn in order and a legend.
void WriteMapPngWithOverlays(const msgs::OccupancyGrid& grid, const std::vector<MapOverlay>& overlays, int scale,
                             const std::string& path);

// An OctoMap (.bt) of the grid for 3D viewers: occupied cells become columns from z = 0 to
// `wall_height_m`, free cells a free floor layer, at the grid's resolution.
void WriteOctomap(const msgs::OccupancyGrid& grid, double wall_height_m, const std::string& path);

// True when `path` has the extension of a map format ReadAnyMap reads.
bool IsMapFile(const std::string& path);

// Reads any of the formats above, chosen by extension and content (simplemaps at 0.05 m).
msgs::OccupancyGrid ReadAnyMap(const std::string& path, std::string* format = nullptr, bool saver_unknown = false);

// A SLAM checkpoint, so an autonomy killed mid-run starts again from what it had mapped: the map as a
// botlab .map beside an INI file ([checkpoint] map, pose and odometry = x, y, theta_deg, t_s, scans). The map is
// written (atomically) before the INI, so an INI always names a whole map.
struct SlamCheckpoint {
  std::string map_path;   // absolute, as read back
  msgs::Pose2D pose;      // the estimate at the last scan
  msgs::Pose2D odometry;  // the robot's odometry then (a resumed run adds what it moved since)
  double t_s = 0.0;       // that scan's time
  long long scans = 0;    // scans processed when it was written
};
// Writes `<ini_path minus .ini>.map` and then `ini_path`.
void WriteSlamCheckpoint(const std::string& ini_path, const msgs::OccupancyGrid& map, const SlamCheckpoint& c);
// Reads a checkpoint INI (its map path is resolved against the INI's folder); throws
// std::runtime_error / config::ConfigError naming the file and key.
SlamCheckpoint ReadSlamCheckpoint(const std::string& ini_path);

}  // namespace mbot::drivers
