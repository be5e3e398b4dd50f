// `referee`: the adapter between the event stream and sim::Referee (libs/sim), the competition's
// judge on the simulator. It feeds the referee the true poses, collisions and the stack's outputs,
// ends the run when the referee says (the mission finished, or the time limit), and at the end
// writes what the score holds: score.json, the trajectories (true, SLAM) as TUM, the final map
// (.map + PNG with the planned, driven and true paths, warehouse stops, collisions), the printed
// rubric and the competition's table row.
#include <chrono>
#include <cmath>
#include <iostream>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/drivers/map_io.hpp"
#include "mbot/reports/score.hpp"
#include "mbot/sim/referee.hpp"
#include "report.hpp"
#include "mbot/msgs/topics.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

using motion::Pose2D;
using msgs::EventKind;

constexpr int kPngScale = 4;  // final_map.png: pixels per map cell

struct RefereeStageOptions {
  sim::RefereeOptions referee;
  std::string mission_status_channel = msgs::topics::kMissionStatus;
  // The score so far, this often on the data's clock, when the run has an output (a viewer); 0: never.
  double score_every_s = 1.0;
};

class RefereeStage : public Stage {
 public:
  explicit RefereeStage(RefereeStageOptions o) : o_(std::move(o)) {}

  void Start(const RunContext& ctx) override {
    bus_ = ctx.bus;
    sim::World world = sim::World::Load(ctx.source_path);
    try {
      referee_ = std::make_unique<sim::Referee>(o_.referee, std::move(world), ctx.seed);
    } catch (const std::invalid_argument& e) {  // the Warehouse and Heavy Lift need more than walls
      throw std::runtime_error("referee: the world " + ctx.source_path + " cannot hold the " +
                               sim::Title(o_.referee.event) + ": " + e.what());
    }
    wall0_ = std::chrono::steady_clock::now();
  }

  void OnEvent(const msgs::Event& ev) override {
    referee_->Tick(ev.t_us);
    switch (ev.kind) {
      case EventKind::kGroundTruth: referee_->OnTruePose(ev.t_us, std::get<Pose2D>(ev.payload)); break;
      case EventKind::kCollision: referee_->OnCollision(ev.t_us, std::get<Pose2D>(ev.payload)); break;
      case EventKind::kCrates: referee_->OnCrates(std::get<msgs::CrateStates>(ev.payload)); break;
      case EventKind::kPoseEstimate: referee_->OnSlamPose(ev.t_us, std::get<Pose2D>(ev.payload)); break;
      case EventKind::kMap: referee_->OnMap(std::get<std::shared_ptr<const mapping::OccupancyGrid>>(ev.payload)); break;
      case EventKind::kPath: path_ = std::get<msgs::Path>(ev.payload).poses; break;
      case EventKind::kSlamStatus:
        referee_->OnSlamState(ev.t_us, std::get<mapping::SlamStatus>(ev.payload).state);
        break;
      case EventKind::kMissionStatus:
        if (ev.channel == o_.mission_status_channel)
          referee_->OnMissionStatus(ev.t_us, std::get<mission::MissionStatus>(ev.payload));
        break;
      default: break;
    }
    if (!bus_) return;
    PublishScore(ev.t_us);
    if (const std::optional<std::string> why = referee_->StopReason(ev.t_us)) bus_->RequestStop(*why);
  }

  void Finish(const RunContext& ctx, bool interrupted) override {
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0_).count();
    const sim::Score s = referee_->Judge();
    if (!s.scored) {
      mbot::log::Warn("referee: no ground truth in the stream (is the source the simulator?); nothing scored");
      return;
    }
    const reports::ScoreContext c{ctx.source_path, referee_->world().name(), ctx.seed, interrupted, wall_s};
    std::cout << reports::RubricText(s, c) << std::flush;

    const std::string dir = ctx.output_dir;
    WriteTum(dir + "/true_path.tum", "", referee_->truth());
    WriteTum(dir + "/slam_path.tum", "", referee_->slam(), s.map_frame);
    if (const auto& map = referee_->map()) {
      drivers::WriteBotlabMap(*map, dir + "/final_map.map");
      std::vector<Pose2D> driven, truth, stops;
      for (const auto& p : referee_->slam()) driven.push_back(p.pose);
      const Pose2D inv = s.map_frame.Inverse();
      for (size_t i = 0; i < referee_->truth().size(); i += 5) truth.push_back(inv.Compose(referee_->truth()[i].pose));
      for (const auto& st : referee_->stops()) stops.push_back(inv.Compose(st.pose));
      std::vector<drivers::MapOverlay> overlays{{truth, 0, 0, 0, false, "true path"},
                                                {driven, 31, 119, 180, false, "SLAM path"}};
      if (!path_.empty()) overlays.push_back({path_, 214, 39, 40, false, "last planned path"});
      if (!stops.empty()) overlays.push_back({stops, 44, 160, 44, true, "targets and drop-offs"});
      std::vector<Pose2D> crates;
      for (const sim::CrateResult& c : s.crates) crates.push_back(inv.Compose(c.final_pose));
      if (!crates.empty()) overlays.push_back({crates, 148, 103, 189, true, "crates at the end"});
      if (s.map && !s.map->unmapped.empty())
        overlays.push_back({s.map->unmapped, 240, 140, 0, true, "reachable space not mapped"});
      std::vector<Pose2D> hits;
      for (const sim::CollisionRecord& r : s.collision_events) hits.push_back(inv.Compose(r.pose));
      // A ring the size of the robot's body where it touched.
      const int ring = static_cast<int>(std::lround(o_.referee.robot_radius_m / map->resolution() * kPngScale));
      if (!hits.empty()) overlays.push_back({hits, 230, 0, 180, true, "collisions", ring});
      drivers::WriteMapPngWithOverlays(mapping::CropToKnown(*map, 0.3), overlays, kPngScale, dir + "/final_map.png");
    }
    reports::WriteJson(dir + "/score.json", reports::ScoreReport(s, c));
    if (ctx.event_result) {
      *ctx.event_result = EventResult{sim::Title(s.event),
                                      c.arena,
                                      ctx.seed,
                                      reports::ScoreResult(s),
                                      s.time_s,
                                      wall_s > 0 ? s.sim_s / wall_s : 0.0,
                                      s.total,
                                      s.max_total,
                                      s.collisions};
    }
  }

 private:
  void PublishScore(int64_t t_us) {
    if (o_.score_every_s <= 0 || !bus_->Watched() ||
        (last_score_us_ >= 0 && t_us - last_score_us_ < o_.score_every_s * 1e6))
      return;
    last_score_us_ = t_us;
    const sim::Score s = referee_->Judge();
    if (!s.scored) return;
    msgs::ScoreStatus out{sim::Title(s.event), s.total, s.max_total, s.collisions, s.sim_s, {}};
    for (const sim::RubricItem& i : s.items) out.items.push_back({i.name, i.detail, i.points, i.max});
    bus_->Emit(this, msgs::Event{t_us, t_us, msgs::topics::kScore, EventKind::kScore, std::move(out)});
  }

  RefereeStageOptions o_;
  int64_t last_score_us_ = -1;
  std::unique_ptr<sim::Referee> referee_;
  Bus* bus_ = nullptr;
  std::chrono::steady_clock::time_point wall0_;
  std::vector<Pose2D> path_;  // the last planned path, for the picture
};

}  // namespace

static StageType RefereeStageType() {
  return {"referee",
          "scores a competition event on the simulator (libs/sim: pose tiers, map quality, time, collisions, crates "
          "lifted and stacked), ends the run "
          "when the mission finishes or time runs out, writes score.json, trajectories and the final map",
          [](config::Section& s) -> std::unique_ptr<Stage> {
            RefereeStageOptions o;
            auto& r = o.referee;
            r.event = s.GetEnum("event", r.event,
                                {{"speed_run", sim::CompetitionEvent::kSpeedRun},
                                 {"maze_explorer", sim::CompetitionEvent::kMazeExplorer},
                                 {"warehouse", sim::CompetitionEvent::kWarehouse},
                                 {"heavy_lift", sim::CompetitionEvent::kHeavyLift}},
                                "which event is scored");
            r.robot_radius_m = s.GetDouble(
                "robot_radius_m", r.robot_radius_m,
                "the floor to map is what a body of this radius reaches from the start (the simulated MBot's "
                "footprint_radius_m) [m]",
                0.01, 2.0);
            r.time_limit_s =
                s.GetDouble("time_limit_s", r.time_limit_s, "the run ends here if the mission has not [s]", 1.0, 1e5);
            r.finish_delay_s = s.GetDouble("finish_delay_s", r.finish_delay_s,
                                           "simulate this long after the mission ends [s]", 0.0, 60.0);
            r.crates = static_cast<int>(s.GetInt("crates", r.crates,
                                                 "heavy_lift: judge only the world's first this many stack assignments "
                                                 "(0: all)",
                                                 0, 1000));
            o.mission_status_channel =
                s.GetString("mission_status_channel", o.mission_status_channel, "channel of the mission's states");
            o.score_every_s =
                s.GetDouble("score_every_s", o.score_every_s,
                            "publish the score so far this often (data time, for a viewer; 0: never)", 0.0, 3600.0);
            return std::make_unique<RefereeStage>(o);
          }};
}

const RegisterStage kRefereeRegistered{RefereeStageType()};

}  // namespace mbot::app
