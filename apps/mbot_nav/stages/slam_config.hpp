// The `slam` stage's options, parsed strictly from its INI section: the session's (libs/mapping:
// the back end, the front end and the policies) and the stage's own — the files it reads (a known
// map, a checkpoint to resume from) and writes (the map, the trajectories, metrics.json).
#pragma once

#include <cstdint>
#include <string>

#include "mbot/mapping/slam_session.hpp"

namespace mbot::config {
class Section;
}

namespace mbot::app {

struct SlamStageOptions {
  mapping::SlamSessionOptions session;
  std::string map_file;  // localization: the known map
  std::string checkpoint_file = "slam_checkpoint.ini";
  std::string resume_from;  // a checkpoint INI (sets map_file and the initial pose)
  // Outputs.
  bool truth_is_reference = false;   // score against the reference channel (CARMEN's corrected poses)
  int64_t score_from_us = 0;         // ATE counts scans from this long after the start
  int64_t score_max_latency_us = 0;  // ... that arrived at most this late (0: all)
  std::string map_basename = "slam_map";
  int png_scale = 2;
  double map_resolution_m = 0;                // the written map's resolution (0: the SLAM's own; graph SLAM only)
  std::string graph_file = "slam_graph.g2o";  // graph SLAM's pose graph, in g2o's format ("" = none)
  double octomap_height_m = 0.3;              // wall height in the OctoMap (0: no .bt)
  bool tum_stamps = false;                    // the TUM files and the relations use the scans' own stamps
  std::string relations_file;                 // a .relations file to score the trajectory on ("" = none)
};

SlamStageOptions ParseSlamStageOptions(config::Section& s);

}  // namespace mbot::app
