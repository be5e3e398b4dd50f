// The parts of the slam stage's metrics.json that graph SLAM and a relations file add: the "graph"
// object (and its log lines) and the "relations" object (Kuemmerle et al.'s metric on slam.tum).
#pragma once

#include <string>
#include <vector>

#include "mbot/mapping/graph_slam.hpp"
#include "mbot/motion/pose2d.hpp"
#include "mbot/motion/relations.hpp"
#include "mbot/reports/json.hpp"

namespace mbot::app {

// The "graph" object: the graph, its loop closures (those the robust loss rejected, listed), its
// time. Logs a summary line and the first rejected closures.
reports::Json GraphSlamJson(const mapping::GraphSlamStats& stats);

// The "relations" object for `path` (the scored trajectory, at the times slam.tum carries). When
// the file does not fit the run, the object holds the error, which is also put in `*error`.
reports::Json RelationsJson(const std::string& relations_file, const std::vector<motion::TimedPose>& path,
                            std::string* error);

}  // namespace mbot::app
