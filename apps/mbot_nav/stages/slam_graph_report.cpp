#include "slam_graph_report.hpp"

#include <map>

#include "mbot/common/log.hpp"
#include "report.hpp"

namespace mbot::app {
namespace {

using reports::Json;
using reports::Number;

Json MeanStdJson(const motion::MeanStd& m) { return {{"mean", Number(m.mean)}, {"std", Number(m.std)}}; }

}  // namespace

Json GraphSlamJson(const mapping::GraphSlamStats& g) {
  mbot::log::Info("slam: graph of " + std::to_string(g.nodes) + " nodes in " + std::to_string(g.submaps) +
                  " submaps; " + std::to_string(g.loop_closures) + " loop closures from " +
                  std::to_string(g.loop_searches) + " searches (" + std::to_string(g.loop_searches_bounded) +
                  " narrowed by the drift bound; " + std::to_string(g.loop_closures_contradicted) +
                  " more dropped as a neighbouring submap placed them elsewhere), " +
                  std::to_string(g.rejected.size()) + " rejected by the robust loss; " +
                  std::to_string(g.sparse_scans) + " scans too sparse to match; " + std::to_string(g.recoveries) +
                  " scans placed by a recovery search (of " + std::to_string(g.recovery_searches) + ", " +
                  std::to_string(g.doubtful_searches) + " for odometry gaps or restarts, " +
                  std::to_string(g.doubtful_bounded) + " across a gap narrowed by the clock at a top speed of " +
                  (g.top_speed_m_s >= 0 ? Num(g.top_speed_m_s, 3) + " m/s" : std::string("(unknown)")) + "); " +
                  std::to_string(g.degenerate_scans) + " scans moved by odometry along a corridor");
  for (size_t i = 0; i < g.rejected.size() && i < 5; ++i) {
    const mapping::RejectedClosure& r = g.rejected[i];
    mbot::log::Warn(
        "slam: loop closure of node " + std::to_string(r.node) + " to submap " + std::to_string(r.submap) + " (score " +
        Num(r.score, 3) + ") rejected by the robust loss (residual " + Num(r.residual, 3) + ")" +
        (i == 4 && g.rejected.size() > 5 ? "; metrics.json lists all " + std::to_string(g.rejected.size()) : ""));
  }
  Json rejected = Json::array();
  for (const mapping::RejectedClosure& r : g.rejected) {
    rejected.push_back(
        {{"node", r.node}, {"submap", r.submap}, {"score", Number(r.score)}, {"residual", Number(r.residual)}});
  }
  return {{"nodes", g.nodes},
          {"submaps", g.submaps},
          {"sparse_scans", g.sparse_scans},
          {"recovery_searches", g.recovery_searches},
          {"recoveries", g.recoveries},
          {"doubtful_searches", g.doubtful_searches},
          {"doubtful_bounded", g.doubtful_bounded},
          {"top_speed_m_s", g.top_speed_m_s >= 0 ? Number(g.top_speed_m_s) : Json(nullptr)},
          {"degenerate_scans", g.degenerate_scans},
          {"loop_searches", g.loop_searches},
          {"loop_closures", g.loop_closures},
          {"loop_searches_bounded", g.loop_searches_bounded},
          {"loop_closures_contradicted", g.loop_closures_contradicted},
          {"loop_closures_unverified", g.loop_closures_unverified},
          {"optimizations", g.optimizations},
          {"front_end_s", Number(g.front_end_s)},
          {"loop_search_s", Number(g.loop_search_s)},
          {"optimize_s", Number(g.optimize_s)},
          {"render_s", Number(g.render_s)},
          {"apply_max_s", Number(g.apply_max_s)},
          {"rejected_closures", std::move(rejected)}};
}

Json RelationsJson(const std::string& file, const std::vector<motion::TimedPose>& path, std::string* error) {
  std::map<int64_t, motion::Pose2D> poses;
  for (const motion::TimedPose& p : path) poses.emplace(p.t_us, p.pose);
  motion::RelationErrors e;
  try {
    e = motion::ScoreRelations(motion::ReadRelations(file), poses, file);
  } catch (const motion::RelationsError& x) {
    *error = x.what();
    return {{"error", *error}};
  }
  mbot::log::Info("slam: relations (" + file + ", " + std::to_string(e.scored) + " of " + std::to_string(e.relations) +
                  " scored): translation " + Num(e.trans_m.mean, 4) + " +- " + Num(e.trans_m.std, 4) + " m, rotation " +
                  Num(e.rot_deg.mean, 3) + " +- " + Num(e.rot_deg.std, 3) + " deg");
  return {{"file", file},
          {"relations", e.relations},
          {"scored", e.scored},
          {"translation_m", MeanStdJson(e.trans_m)},
          {"rotation_deg", MeanStdJson(e.rot_deg)},
          {"translation_sq_m2", MeanStdJson(e.trans_sq_m2)},
          {"rotation_sq_deg2", MeanStdJson(e.rot_sq_deg2)},
          {"max_translation_m", Number(e.max_trans_m)},
          {"max_rotation_deg", Number(e.max_rot_deg)}};
}

}  // namespace mbot::app
