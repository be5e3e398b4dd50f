// INI parsing for the mapping options (one function per options struct, beside the structs). The
// algorithm headers never see the INI reader; only this file does.
#pragma once

#include "mbot/mapping/action_model.hpp"
#include "mbot/mapping/graph_slam.hpp"
#include "mbot/mapping/log_odds_mapper.hpp"
#include "mbot/mapping/moving_scan.hpp"
#include "mbot/mapping/particle_filter.hpp"
#include "mbot/mapping/sensor_model.hpp"
#include "mbot/mapping/slam.hpp"

namespace mbot::config {
class Section;
}

namespace mbot::mapping {

// Keys min_range_m, max_range_m, no_return_clear_m.
ScanOptions ParseScanOptions(config::Section& section, const ScanOptions& defaults = {});
// Keys hit_odds, miss_odds, resolution_m, width_m, height_m, center_x_m, center_y_m, grow.
MapperOptions ParseMapperOptions(config::Section& section, const MapperOptions& defaults = {});
// Keys k1, k2, min_sigma_trans_m, min_sigma_rot_rad, min_trans_m, min_rot_rad.
ActionModelOptions ParseActionModelOptions(config::Section& section, const ActionModelOptions& defaults = {});
// Keys sensor_model (likelihood_field | simplified), ray_stride, sigma_m, max_distance_m,
// random_weight, log_scale, odds_scale, neighbour_weight, inlier_distance_m.
SensorModelOptions ParseSensorModelOptions(config::Section& section, const SensorModelOptions& defaults = {});
// The particle filter's keys (particles, threads, global localization, augmented MCL, lost). The
// mode, not `defaults`, decides the defaults of augmented and relocalize_when_lost: on for
// localization, off for the mapping modes.
ParticleFilterOptions ParseParticleFilterOptions(config::Section& section, SlamMode mode,
                                                 const ParticleFilterOptions& defaults = {});
// The graph-SLAM keys (graph_*): submaps, front end, constraint weights, loop closure, solves.
GraphSlamOptions ParseGraphSlamOptions(config::Section& section, const GraphSlamOptions& defaults = {});
// Key mode (full_slam | localization | mapping_only | action_only | graph_slam) and every key above but the scan's.
// Throws config::ConfigError naming the section and key.
SlamOptions ParseSlamOptions(config::Section& section);

}  // namespace mbot::mapping
