// `referee`: the adapter between the event stream and sim::Referee (libs/sim), the competition's
// judge on the simulator. It feeds the referee the true poses, collisions and the stack's outputs,
// ends the run when the referee says (the mission finished, or the time limit), and at the end
// writes what the score holds: score.json, the trajectories (true, SLAM) as TUM, the final map
// (.map + PNG with the planned, driven and true paths, warehouse stops), the printed rubric and the
// competition's table row.
#include <chrono>
#include <iomanip>
#include <iostream>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/drivers/map_io.hpp"
#include "mbot/sim/referee.hpp"
#include "report.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

using drivers::EventKind;
using motion::Pose2D;

struct RefereeStageOptions {
  sim::RefereeOptions referee;
  std::string mission_status_channel = "MISSION_STATUS";
};

std::string ErrorJson(const sim::PoseError& e) {
  return "{\"x_m\": " + Num(e.x_m) + ", \"y_m\": " + Num(e.y_m) + ", \"theta_deg\": " + Num(e.theta_deg) + "}";
}

// score.json: the score as the rubric counts it.
std::string ScoreJson(const sim::Score& s, const RunContext& ctx, const std::string& arena, bool interrupted,
                      double wall_s) {
  const double rtf = wall_s > 0 ? s.sim_s / wall_s : 0.0;
  std::ostringstream j;
  j << "{\n  \"event\": " << JsonString(sim::ToString(s.event)) << ",\n  \"world\": " << JsonString(ctx.source_path)
    << ",\n  \"arena\": " << JsonString(arena) << ",\n  \"seed\": " << ctx.seed
    << ",\n  \"state\": " << JsonString(mission::ToString(s.state)) << ",\n  \"detail\": " << JsonString(s.detail)
    << ",\n  \"completed\": " << (s.completed ? "true" : "false")
    << ",\n  \"incomplete\": " << (s.incomplete ? "true" : "false")
    << ",\n  \"timed_out\": " << (s.timed_out ? "true" : "false")
    << ",\n  \"interrupted\": " << (interrupted ? "true" : "false") << ",\n  \"time_s\": " << Num(s.time_s)
    << ",\n  \"sim_seconds\": " << Num(s.sim_s) << ",\n  \"wall_seconds\": " << Num(wall_s)
    << ",\n  \"real_time_factor\": " << Num(rtf) << ",\n  \"collisions\": " << s.collisions
    << ",\n  \"start\": " << PoseJson(s.start) << ",\n  \"final\": " << PoseJson(s.final_pose);
  if (s.final_error) j << ",\n  \"final_error\": " << ErrorJson(*s.final_error);
  if (s.slam_final_error) j << ",\n  \"slam_final_error\": " << ErrorJson(*s.slam_final_error);
  if (s.map) {
    j << ",\n  \"map\": {\"coverage\": " << Num(s.map->coverage)
      << ", \"coverage_one_cell\": " << Num(s.map->coverage_one_cell)
      << ", \"wall_precision\": " << Num(s.map->precision) << ", \"reachable_cells\": " << s.map->reachable_cells
      << ", \"occupied_cells\": " << s.map->occupied_cells << "}";
  }
  if (s.event == sim::CompetitionEvent::kWarehouse) {
    j << ",\n  \"localized_at_s\": " << (s.localized_at_s ? Num(*s.localized_at_s) : "null")
      << ",\n  \"levels_reached\": " << s.levels_reached << ",\n  \"stops\": [";
    for (size_t k = 0; k < s.stops.size(); ++k) {
      const sim::StopResult& r = s.stops[k];
      j << (k ? "," : "") << "\n    {\"stop\": " << JsonString(r.stop.Name()) << ", \"pose\": " << PoseJson(r.stop.pose)
        << ", \"done_at_s\": " << (r.done_at_s ? Num(*r.done_at_s) : "null")
        << ", \"missed\": " << (r.missed ? "true" : "false") << "}";
    }
    j << "\n  ]";
  }
  if (s.event == sim::CompetitionEvent::kHeavyLift) {
    j << ",\n  \"crates\": [";
    for (size_t k = 0; k < s.crates.size(); ++k) {
      const sim::CrateResult& c = s.crates[k];
      j << (k ? "," : "") << "\n    {\"id\": " << c.id << ", \"on\": " << c.on_id
        << ", \"lifted\": " << (c.lifted ? "true" : "false") << ", \"stacked\": " << (c.stacked ? "true" : "false")
        << ", \"fell\": " << (c.fell ? "true" : "false") << ", \"final\": " << PoseJson(c.final_pose)
        << ", \"final_z_m\": " << Num(c.final_z_m) << "}";
    }
    j << "\n  ]";
  }
  j << ",\n  \"points\": {";
  for (const sim::RubricItem& i : s.items) j << JsonString(i.name) << ": " << i.points << ", ";
  j << "\"total\": " << s.total << ", \"max\": " << s.max_total << "}\n}\n";
  return j.str();
}

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

  void OnEvent(const drivers::Event& ev) override {
    referee_->Tick(ev.t_us);
    switch (ev.kind) {
      case EventKind::kGroundTruth: referee_->OnTruePose(ev.t_us, std::get<Pose2D>(ev.payload)); break;
      case EventKind::kCollision: referee_->OnCollision(); break;
      case EventKind::kCrates: referee_->OnCrates(std::get<drivers::CrateStates>(ev.payload)); break;
      case EventKind::kPoseEstimate: referee_->OnSlamPose(ev.t_us, std::get<Pose2D>(ev.payload)); break;
      case EventKind::kMap: referee_->OnMap(std::get<std::shared_ptr<const mapping::OccupancyGrid>>(ev.payload)); break;
      case EventKind::kPath: path_ = std::get<drivers::Path>(ev.payload).poses; break;
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
    if (const std::optional<std::string> why = referee_->StopReason(ev.t_us)) bus_->RequestStop(*why);
  }

  void Finish(const RunContext& ctx, bool interrupted) override {
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0_).count();
    const sim::Score s = referee_->Judge();
    if (!s.scored) {
      mbot::log::Warn("referee: no ground truth in the stream (is the source the simulator?); nothing scored");
      return;
    }
    const std::string arena = referee_->world().name();
    const std::string result = s.timed_out ? "time limit" : mission::ToString(s.state);
    const double rtf = wall_s > 0 ? s.sim_s / wall_s : 0.0;
    std::ostringstream t;
    t << "\n"
      << sim::Title(s.event) << " - arena " << arena << ", seed " << ctx.seed << ": " << result << " after "
      << Num(s.time_s, 4) << " s (" << Num(rtf, 3) << "x real time), " << s.collisions << " collisions\n";
    for (const sim::RubricItem& i : s.items) {
      t << "  " << std::left << std::setw(20) << i.name << std::setw(68) << i.detail << std::right << std::setw(4)
        << i.points << " / " << i.max << "\n";
    }
    t << "  " << std::left << std::setw(88) << "total" << std::right << std::setw(4) << s.total << " / " << s.max_total
      << "\n";
    std::cout << t.str() << std::flush;

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
      drivers::WriteMapPngWithOverlays(mapping::CropToKnown(*map, 0.3), overlays, 4, dir + "/final_map.png");
    }
    WriteFileAtomically(dir + "/score.json",
                        [&](std::ostream& out) { out << ScoreJson(s, ctx, arena, interrupted, wall_s); });
    if (ctx.event_result) {
      *ctx.event_result =
          EventResult{sim::Title(s.event), arena, ctx.seed, result, s.time_s, rtf, s.total, s.max_total, s.collisions};
    }
  }

 private:
  RefereeStageOptions o_;
  std::unique_ptr<sim::Referee> referee_;
  Bus* bus_ = nullptr;
  std::chrono::steady_clock::time_point wall0_;
  std::vector<Pose2D> path_;  // the last planned path, for the picture
};

}  // namespace

StageType RefereeStageType() {
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
            return std::make_unique<RefereeStage>(o);
          }};
}

}  // namespace mbot::app
