#include "slam_config.hpp"

#include <cmath>

#include "mbot/common/config.hpp"
#include "mbot/drivers/map_io.hpp"

namespace mbot::app {

SlamStageOptions ParseSlamStageOptions(config::Section& s) {
  SlamStageOptions o;
  o.session = mapping::ParseSlamSessionOptions(s);
  const mapping::SlamOptions& m = o.session.slam;
  o.map_file = s.GetPath("map_file", "",
                         "localization: the known map; graph_slam with initial_pose = global: the finished map the "
                         "first scan is found on by a whole-map search (any format the map reader knows)");
  if (m.mode == mapping::SlamMode::kLocalization && o.map_file.empty() && !s.describing()) {
    s.Fail("map_file", "localization mode needs a map_file");
  }
  if (m.mode == mapping::SlamMode::kGraphSlam && !s.describing()) {
    if (o.session.initial == "global" && o.map_file.empty())
      s.Fail("initial_pose", "global in graph_slam mode needs a map_file to search");
    if (o.session.initial != "global" && !o.map_file.empty())
      s.Fail("map_file", "graph_slam reads a map_file only with initial_pose = global (the map to start on)");
  }
  o.session.known_map_name = o.map_file;
  o.truth_is_reference = s.GetChoice("truth", "ground_truth", {"ground_truth", "reference"},
                                     "what metrics.json scores against") == "reference";
  o.checkpoint_file = s.GetString("checkpoint_file", "slam_checkpoint.ini",
                                  "the checkpoint's INI, in the output folder (its map beside it, as .map)");
  o.resume_from = s.GetPath("resume_from", "",
                            "a checkpoint INI to start from: its map becomes map_file and its pose the initial_pose "
                            "(for full SLAM the map keeps growing)");
  if (!o.resume_from.empty() && !s.describing()) {
    if (m.mode == mapping::SlamMode::kMappingOnly || m.mode == mapping::SlamMode::kActionOnly) {
      s.Fail("resume_from", "needs mode = full_slam or localization (a map to localize in)");
    }
    try {
      const drivers::SlamCheckpoint c = drivers::ReadSlamCheckpoint(o.resume_from);
      o.map_file = c.map_path;
      o.session.initial = "pose";
      o.session.initial_pose = c.pose;
      o.session.resume_odometry = c.odometry;
    } catch (const std::exception& e) {
      s.Fail("resume_from", e.what());
    }
  }

  // Outputs.
  o.score_from_us = static_cast<int64_t>(
      s.GetDouble("score_from_s", 0.0, "ATE counts scans from this long after the start", 0.0) * 1e6);
  o.score_max_latency_us = static_cast<int64_t>(
      s.GetDouble("score_max_latency_s", 0.0,
                  "ATE skips scans that reached the logger later than this after their stamp "
                  "(the logged motion capture is stamped on arrival and is late too); 0: score all",
                  0.0) *
      1e6);
  o.map_basename = s.GetString("map_basename", o.map_basename, "map files in output.dir: .map, .pgm/.yaml, .png, .bt");
  o.map_resolution_m = s.GetDouble("map_resolution_m", 0.0,
                                   "the written map's cell size: graph SLAM renders every scan again at its optimised "
                                   "pose at this resolution after the run (0: the SLAM's own resolution_m)",
                                   0.0, 10.0);
  if (o.map_resolution_m > 0 && m.mode != mapping::SlamMode::kGraphSlam && !s.describing())
    s.Fail("map_resolution_m", "needs mode = graph_slam (the other modes keep no scans to render again)");
  o.graph_file = s.GetString("graph_file", o.graph_file,
                             "graph SLAM: the pose graph in g2o's text format (VERTEX_SE2 / EDGE_SE2), in the output "
                             "folder (empty: none)");
  o.png_scale = static_cast<int>(s.GetInt("png_scale", o.png_scale, "pixels per map cell in the PNG", 1, 16));
  o.octomap_height_m =
      s.GetDouble("octomap_height_m", o.octomap_height_m, "wall height in the OctoMap .bt (0: none)", 0.0);
  o.tum_stamps = s.GetChoice("tum_time", "event", {"event", "stamp"},
                             "times in the TUM files and for the relations: each scan's event time, or its own "
                             "stamp (CARMEN logs read in file order)") == "stamp";
  o.relations_file =
      s.GetPath("relations", "", "score slam.tum on this Kuemmerle et al. .relations file (metrics.json 'relations')");
  return o;
}

}  // namespace mbot::app
