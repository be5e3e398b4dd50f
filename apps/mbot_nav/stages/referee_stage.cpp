// `referee`: scores a competition event run on the simulator (Winter 2024 rules, as the issue states
// them) from what only the simulator knows — the true pose, the true walls, collisions — and what
// the stack produced — its SLAM map and poses, its paths, its mission states. It ends the run when
// the mission completes or fails, or at the event's time limit. Writes score.json, the trajectories
// (true, SLAM) as TUM, the final map (.map + PNG with the planned, driven and true paths) and prints
// the score table.
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/drivers/map_io.hpp"
#include "mbot/drivers/sim_world.hpp"
#include "report.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

using drivers::EventKind;
using motion::Pose2D;
using motion::TimedPose;

struct RefereeOptions {
  std::string event = "speed_run";  // speed_run | maze_explorer
  double time_limit_s = 180.0;
  double finish_delay_s = 0.5;      // keep simulating this long after completion (the robot stops)
};

// Points for a final pose error, the rubric's tiers (x, y in m; θ in degrees).
int PosePoints(double ex, double ey, double eth_deg) {
  struct Tier {
    double xy, th;
    int points;
  };
  for (const Tier& t : {Tier{0.03, 15, 100}, Tier{0.05, 15, 75}, Tier{0.10, 30, 50}, Tier{0.20, 45, 25}}) {
    if (ex < t.xy && ey < t.xy && eth_deg < t.th) return t.points;
  }
  return 0;
}

int LapPoints(double s) { return s < 15 ? 100 : s < 20 ? 75 : s < 30 ? 50 : 0; }

struct MapQuality {
  double coverage = 0;   // share of the reachable free space (≥ one SLAM cell from walls) mapped free
  double precision = 0;  // share of the mapped walls within one SLAM cell of a true wall
  int reachable_cells = 0, occupied_cells = 0;
};

class RefereeStage : public Stage {
 public:
  explicit RefereeStage(RefereeOptions o) : o_(std::move(o)) {}

  void Start(const RunContext& ctx) override {
    bus_ = ctx.bus;
    world_ = drivers::World::Load(ctx.source_path);
    wall0_ = std::chrono::steady_clock::now();
  }

  void OnEvent(const drivers::Event& ev) override {
    if (t0_us_ < 0) t0_us_ = ev.t_us;
    last_us_ = ev.t_us;
    switch (ev.kind) {
      case EventKind::kGroundTruth:
        truth_.push_back({ev.t_us, std::get<Pose2D>(ev.payload)});
        break;
      case EventKind::kCollision:
        ++collisions_;
        break;
      case EventKind::kPoseEstimate:
        slam_.push_back({ev.t_us, std::get<Pose2D>(ev.payload)});
        break;
      case EventKind::kMap:
        map_ = std::get<std::shared_ptr<const mapping::OccupancyGrid>>(ev.payload);
        break;
      case EventKind::kPath:
        path_ = std::get<drivers::Path>(ev.payload).poses;
        break;
      case EventKind::kStatus: {
        const auto& s = std::get<drivers::Status>(ev.payload);
        state_ = s.state, detail_ = s.detail;
        if ((s.state == "completed" || s.state == "failed") && end_us_ < 0) end_us_ = ev.t_us;
        break;
      }
      default:
        break;
    }
    if (!bus_ || stop_sent_) return;
    if (end_us_ >= 0 && (ev.t_us - end_us_) * 1e-6 >= o_.finish_delay_s) {
      stop_sent_ = true;
      bus_->RequestStop("referee: the mission " + state_);
    } else if ((ev.t_us - t0_us_) * 1e-6 >= o_.time_limit_s) {
      stop_sent_ = true;
      timed_out_ = true;
      bus_->RequestStop("referee: time limit of " + Num(o_.time_limit_s, 4) + " s");
    }
  }

  void Finish(const RunContext& ctx, bool interrupted) override {
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0_).count();
    const double sim_s = t0_us_ >= 0 ? (last_us_ - t0_us_) * 1e-6 : 0.0;
    if (truth_.empty()) {
      mbot::log::Warn("referee: no ground truth in the stream (is the source the simulator?); nothing scored");
      return;
    }
    const Pose2D start = truth_.front().pose, final_pose = truth_.back().pose;
    const double ex = std::abs(final_pose.x - start.x), ey = std::abs(final_pose.y - start.y);
    const double eth = std::abs(motion::WrapAngle(final_pose.theta - start.theta)) * 180.0 / M_PI;
    const bool completed = state_ == "completed";
    const int pose_points = completed ? PosePoints(ex, ey, eth) : 0;
    const double time_s = end_us_ >= 0 ? (end_us_ - t0_us_) * 1e-6 : sim_s;
    const MapQuality mq = map_ ? Quality(*map_, start) : MapQuality{};
    const int map_points = static_cast<int>(std::floor(100.0 * std::min(1.0, std::min(mq.coverage / 0.99, mq.precision / 0.95))));
    int time_points = 0, autonomy_points = 0;
    if (o_.event == "speed_run") time_points = completed ? LapPoints(time_s) : 0;
    if (o_.event == "maze_explorer") autonomy_points = completed ? 100 : 0;  // no human touched it
    const int total = pose_points + map_points + time_points + autonomy_points;
    const double rtf = wall_s > 0 ? sim_s / wall_s : 0.0;

    std::ostringstream t;
    t << "\n" << std::left << std::setw(15) << "event" << std::setw(18) << "arena" << std::setw(6) << "seed" << std::setw(11)
      << "result" << std::right << std::setw(8) << "time s" << std::setw(22) << "final err x/y m, deg" << std::setw(6) << "pose"
      << std::setw(9) << "map cov" << std::setw(6) << "map" << std::setw(6) << "time" << std::setw(6) << "auto" << std::setw(7)
      << "total" << std::setw(6) << "hits" << std::setw(7) << "RTF" << "\n";
    char err[64];
    std::snprintf(err, sizeof err, "%.3f/%.3f/%.1f", ex, ey, eth);
    t << std::left << std::setw(15) << o_.event << std::setw(18) << world_.name().substr(0, 17) << std::setw(6) << ctx.seed
      << std::setw(11) << (timed_out_ ? "time limit" : state_) << std::right << std::fixed << std::setprecision(1) << std::setw(8)
      << time_s << std::setw(22) << err << std::setw(6) << pose_points << std::setw(8) << std::setprecision(1)
      << 100 * mq.coverage << "%" << std::setw(6) << map_points << std::setw(6) << time_points << std::setw(6)
      << autonomy_points << std::setw(7) << total << std::setw(6) << collisions_ << std::setw(6) << std::setprecision(0)
      << rtf << "x\n";
    t << "(Heavy Lift needs the forklift and AprilTag vision: not run. Warehouse: not yet in this build.)\n";
    std::cout << t.str() << std::flush;

    std::ostringstream j;
    j << "{\n  \"event\": " << JsonString(o_.event) << ",\n  \"world\": " << JsonString(ctx.source_path)
      << ",\n  \"arena\": " << JsonString(world_.name()) << ",\n  \"seed\": " << ctx.seed
      << ",\n  \"state\": " << JsonString(state_) << ",\n  \"detail\": " << JsonString(detail_)
      << ",\n  \"completed\": " << (completed ? "true" : "false") << ",\n  \"timed_out\": " << (timed_out_ ? "true" : "false")
      << ",\n  \"interrupted\": " << (interrupted ? "true" : "false") << ",\n  \"time_s\": " << Num(time_s)
      << ",\n  \"sim_seconds\": " << Num(sim_s) << ",\n  \"wall_seconds\": " << Num(wall_s) << ",\n  \"real_time_factor\": " << Num(rtf)
      << ",\n  \"collisions\": " << collisions_ << ",\n  \"start\": " << PoseJson(start) << ",\n  \"final\": " << PoseJson(final_pose)
      << ",\n  \"final_error\": {\"x_m\": " << Num(ex) << ", \"y_m\": " << Num(ey) << ", \"theta_deg\": " << Num(eth) << "}"
      << ",\n  \"map\": {\"coverage\": " << Num(mq.coverage) << ", \"wall_precision\": " << Num(mq.precision)
      << ", \"reachable_cells\": " << mq.reachable_cells << ", \"occupied_cells\": " << mq.occupied_cells << "}"
      << ",\n  \"points\": {\"pose\": " << pose_points << ", \"map\": " << map_points << ", \"time\": " << time_points
      << ", \"autonomy\": " << autonomy_points << ", \"total\": " << total << "}\n}\n";
    const std::string dir = ctx.output_dir;
    WriteTum(dir + "/true_path.tum", truth_, Pose2D{});
    WriteTum(dir + "/slam_path.tum", slam_, start);
    if (map_) {
      drivers::WriteBotlabMap(*map_, dir + "/final_map.map");
      std::vector<drivers::MapOverlay> overlays;
      std::vector<Pose2D> driven, truth;
      for (const auto& p : slam_) driven.push_back(p.pose);
      const Pose2D inv = start.Inverse();
      for (size_t i = 0; i < truth_.size(); i += 5) truth.push_back(inv.Compose(truth_[i].pose));
      overlays.push_back({truth, 0, 0, 0, false, "true path"});
      overlays.push_back({driven, 31, 119, 180, false, "SLAM path"});
      if (!path_.empty()) overlays.push_back({path_, 214, 39, 40, false, "last planned path"});
      drivers::WriteMapPngWithOverlays(*map_, overlays, 4, dir + "/final_map.png");
    }
    WriteFileAtomically(dir + "/score.json", [&](std::ostream& out) { out << j.str(); });
  }

 private:
  // The SLAM map is in the start frame; the true walls in the world frame.
  MapQuality Quality(const mapping::OccupancyGrid& m, const Pose2D& start) const {
    MapQuality q;
    const mapping::OccupancyGrid& truth = world_.truth();
    const std::vector<uint8_t> reach = drivers::ReachableFreeMask(world_, start);
    const Pose2D inv = start.Inverse();
    int mapped = 0;
    for (int cy = 0; cy < truth.height(); ++cy) {
      for (int cx = 0; cx < truth.width(); ++cx) {
        if (!reach[static_cast<size_t>(cy) * truth.width() + cx]) continue;
        double x, y;
        truth.CellToWorld(cx, cy, &x, &y);
        if (world_.ClearanceAt(x, y) < m.resolution()) continue;  // "walls within one cell"
        ++q.reachable_cells;
        const Pose2D p = inv.Compose(Pose2D{x, y, 0});
        int mx, my;
        m.WorldToCell(p.x, p.y, &mx, &my);
        if (m.IsInside(mx, my) && m.at(mx, my) < 0) ++mapped;
      }
    }
    q.coverage = q.reachable_cells ? double(mapped) / q.reachable_cells : 0.0;
    int near_wall = 0;
    for (int cy = 0; cy < m.height(); ++cy) {
      for (int cx = 0; cx < m.width(); ++cx) {
        if (m.at(cx, cy) <= 0) continue;
        ++q.occupied_cells;
        double x, y;
        m.CellToWorld(cx, cy, &x, &y);
        const Pose2D w = start.Compose(Pose2D{x, y, 0});
        if (world_.ClearanceAt(w.x, w.y) <= 1.5 * m.resolution()) ++near_wall;
      }
    }
    q.precision = q.occupied_cells ? double(near_wall) / q.occupied_cells : 0.0;
    return q;
  }

  static void WriteTum(const std::string& path, const std::vector<TimedPose>& poses, const Pose2D& frame) {
    WriteFileAtomically(path, [&](std::ostream& out) {
      out << "# t x y z qx qy qz qw\n";
      for (const auto& p : poses) {
        const Pose2D w = frame.Compose(p.pose);
        out << TumLine(p.t_us * 1e-6, w.x, w.y, w.theta);
      }
    });
  }

  RefereeOptions o_;
  Bus* bus_ = nullptr;
  drivers::World world_;
  std::chrono::steady_clock::time_point wall0_;
  int64_t t0_us_ = -1, last_us_ = 0, end_us_ = -1;
  std::vector<TimedPose> truth_, slam_;
  std::shared_ptr<const mapping::OccupancyGrid> map_;
  std::vector<Pose2D> path_;
  std::string state_ = "initializing", detail_;
  int collisions_ = 0;
  bool stop_sent_ = false, timed_out_ = false;
};

}  // namespace

StageType RefereeStageType() {
  return {"referee",
          "scores a competition event on the simulator (pose tiers, map quality, time, collisions), ends the run when "
          "the mission finishes or time runs out, writes score.json, trajectories and the final map",
          [](config::Section& s) -> std::unique_ptr<Stage> {
            RefereeOptions o;
            o.event = s.GetChoice("event", o.event, {"speed_run", "maze_explorer"}, "which event is scored");
            o.time_limit_s = s.GetDouble("time_limit_s", o.time_limit_s, "the run ends here if the mission has not [s]", 1.0, 1e5);
            o.finish_delay_s = s.GetDouble("finish_delay_s", o.finish_delay_s, "simulate this long after the mission ends [s]", 0.0, 60.0);
            return std::make_unique<RefereeStage>(o);
          }};
}

}  // namespace mbot::app
