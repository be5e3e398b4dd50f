// The writer of the `slam` stage's outputs from what its session recorded: the map (.map, PGM +
// YAML, a PNG with the SLAM, odometry and ground-truth paths, an OctoMap), the trajectories as TUM,
// slam_scans.csv and metrics.json (ATE per axis under each alignment, global localization,
// kidnapping, timing, map consistency).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "mbot/mapping/slam_record_writer.hpp"
#include "mbot/mapping/slam_session.hpp"
#include "mbot/motion/pose2d.hpp"
#include "slam_config.hpp"
#include "stages.hpp"

namespace mbot::app {

// Writes the map, metrics.json and the rest of a finished session's outputs, after committing the
// streamed ones.
void WriteSlamOutputs(const RunContext& ctx, bool interrupted, const SlamStageOptions& options,
                      const mapping::SlamSession& session, mapping::SlamRecordWriter& records, double wall_s);

}  // namespace mbot::app
