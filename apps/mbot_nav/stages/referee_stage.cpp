// `referee`: scores a competition event run on the simulator (Winter 2024 rules, as the issue states
// them) from what only the simulator knows — the true pose, the true walls, collisions — and what
// the stack produced — its SLAM map and poses, its paths, its mission states. It ends the run when
// the mission completes or fails, or at the event's time limit. Writes score.json, the trajectories
// (true, SLAM) as TUM, the final map (.map + PNG with the planned, driven and true paths) and prints
// the score table. Events: speed_run and maze_explorer (SLAM from the start pose: the map frame is
// the start frame), warehouse (localization in the given map: the map frame is the world frame;
// deliveries judged from the true pose against warehouse.hpp's rules).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/drivers/map_io.hpp"
#include "mbot/sim/world.hpp"
#include "report.hpp"
#include "stages.hpp"
#include "mbot/mission/warehouse_rules.hpp"

namespace mbot::app {
namespace {

namespace warehouse = mission::warehouse;

using drivers::EventKind;
using motion::Pose2D;
using motion::TimedPose;

struct RefereeOptions {
  std::string event = "speed_run";  // speed_run | maze_explorer | warehouse
  double time_limit_s = 180.0;
  double finish_delay_s = 0.5;      // keep simulating this long after completion (the robot stops)
  std::string mission_status_channel = "MISSION_STATUS";
};

const char* EventTitle(const std::string& event) {
  return event == "speed_run" ? "Speed Run" : event == "maze_explorer" ? "Maze Explorer" : event == "warehouse" ? "Warehouse" : "?";
}

// One line of the rubric: what was judged, how it went, the points.
struct Item {
  std::string name, detail;
  int points = 0, max = 100;
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
    world_ = sim::World::Load(ctx.source_path);
    if (o_.event == "warehouse") {
      try {
        stops_ = warehouse::Stops(world_.PosesLabelled("target"), world_.PosesLabelled("dropoff"), ctx.seed);
      } catch (const std::invalid_argument& e) {
        throw std::runtime_error("referee: the world " + ctx.source_path + " has no Warehouse ('pose target' and 'pose dropoff' lines): " + e.what());
      }
    }
    wall0_ = std::chrono::steady_clock::now();
  }

  void OnEvent(const drivers::Event& ev) override {
    if (t0_us_ < 0) t0_us_ = ev.t_us;
    last_us_ = ev.t_us;
    switch (ev.kind) {
      case EventKind::kGroundTruth:
        truth_.push_back({ev.t_us, std::get<Pose2D>(ev.payload)});
        if (!stops_.empty()) JudgeStop(truth_.back());
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
      case EventKind::kSlamStatus:
        if (std::get<mapping::SlamStatus>(ev.payload).state == mapping::SlamState::kLocalized && localized_us_ < 0) {
          localized_us_ = ev.t_us;
        }
        break;
      case EventKind::kMissionStatus: {
        if (ev.channel != o_.mission_status_channel) break;
        const auto& s = std::get<mission::MissionStatus>(ev.payload);
        state_ = s.state, detail_ = s.detail;
        if (mission::IsFinal(s.state) && end_us_ < 0) end_us_ = ev.t_us;
        break;
      }
      default:
        break;
    }
    if (!bus_ || stop_sent_) return;
    if (end_us_ >= 0 && (ev.t_us - end_us_) * 1e-6 >= o_.finish_delay_s) {
      stop_sent_ = true;
      bus_->RequestStop(std::string("referee: the mission ") + mission::ToString(state_));
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
    const bool warehouse = o_.event == "warehouse";
    const Pose2D start = truth_.front().pose, final_pose = truth_.back().pose;
    // Where the map frame lies in the world: SLAM began at the origin at the start pose, or the map
    // was given in the world frame (the Warehouse).
    const Pose2D frame = warehouse ? Pose2D{} : start;
    const bool completed = state_ == mission::MissionState::kCompleted;
    const double time_s = end_us_ >= 0 ? (end_us_ - t0_us_) * 1e-6 : sim_s;
    const double rtf = wall_s > 0 ? sim_s / wall_s : 0.0;
    // Final pose against the start (the robot had to come back), and SLAM's own error at its last pose.
    const double ex = std::abs(final_pose.x - start.x), ey = std::abs(final_pose.y - start.y);
    const double eth = std::abs(motion::WrapAngle(final_pose.theta - start.theta)) * 180.0 / M_PI;
    bool has_slam_error = false;
    double sx = 0, sy = 0, sth = 0;
    if (!slam_.empty()) {
      Pose2D truth_then;
      if (motion::InterpolateAt(truth_, slam_.back().t_us, 200'000, &truth_then)) {
        const Pose2D est = frame.Compose(slam_.back().pose);
        has_slam_error = true;
        sx = std::abs(est.x - truth_then.x), sy = std::abs(est.y - truth_then.y);
        sth = std::abs(motion::WrapAngle(est.theta - truth_then.theta)) * 180.0 / M_PI;
      }
    }
    auto errors = [](double x, double y, double th) {
      char b[80];
      std::snprintf(b, sizeof b, "%.3f / %.3f m, %.1f deg", x, y, th);
      return std::string(b);
    };

    std::vector<Item> items;
    MapQuality mq;
    int levels_reached = 0;
    if (!warehouse) {
      items.push_back({"final pose", errors(ex, ey, eth) + " from the start" + (completed ? "" : " (not completed)"),
                       completed ? PosePoints(ex, ey, eth) : 0});
      mq = map_ ? Quality(*map_, start) : MapQuality{};
      items.push_back({"map quality", "coverage " + Num(100 * mq.coverage, 3) + " %, walls " + Num(100 * mq.precision, 3) +
                                          " % within 1.5 cells",
                       static_cast<int>(std::floor(100.0 * std::min(1.0, std::min(mq.coverage / 0.99, mq.precision / 0.95))))});
      if (o_.event == "speed_run") items.push_back({"lap time", Num(time_s, 4) + " s", completed ? LapPoints(time_s) : 0});
      if (o_.event == "maze_explorer") {
        items.push_back({"autonomy", completed ? "explored and home, no help" : "not completed", completed ? 100 : 0});
      }
    } else {
      const bool localized = localized_us_ >= 0;
      items.push_back({"localization",
                       localized ? "settled in " + Num((localized_us_ - t0_us_) * 1e-6, 3) + " s; at the end SLAM off by " +
                                       errors(sx, sy, sth)
                                 : "global localization never settled",
                       localized && has_slam_error ? PosePoints(sx, sy, sth) : 0});
      // A delivery is made when its target and its drop-off were both done; it counts at the drop-off.
      std::vector<double> made_at_s;
      for (size_t k = 1; k < stop_done_us_.size(); k += 2) {
        if (stop_done_us_[k - 1] >= 0 && stop_done_us_[k] >= 0) made_at_s.push_back((stop_done_us_[k] - t0_us_) * 1e-6);
      }
      int needed = 0;
      for (size_t l = 0; l < warehouse::Levels().size(); ++l) {
        const warehouse::Level& level = warehouse::Levels()[l];
        needed += level.deliveries;
        const int in_time = static_cast<int>(
            std::count_if(made_at_s.begin(), made_at_s.end(), [&](double t) { return t <= level.deadline_s; }));
        // Levels are climbed in order: a level counts when the ones below it did.
        const bool reached = in_time >= needed && levels_reached == static_cast<int>(l);
        if (reached) levels_reached = static_cast<int>(l) + 1;
        items.push_back({"level " + std::to_string(l + 1),
                         std::to_string(std::min(in_time, needed)) + " of " + std::to_string(needed) +
                             (needed == 1 ? " delivery" : " deliveries") + " by " + Num(level.deadline_s, 4) + " s" +
                             (reached ? " (the last at " + Num(made_at_s[needed - 1], 4) + " s)" : ""),
                         reached ? 100 : 0});
      }
    }
    int total = 0, max_total = 0;
    for (const Item& i : items) total += i.points, max_total += i.max;

    std::ostringstream t;
    const std::string result = timed_out_ ? "time limit" : mission::ToString(state_);
    t << "\n" << EventTitle(o_.event) << " - arena " << world_.name() << ", seed " << ctx.seed << ": " << result << " after "
      << Num(time_s, 4) << " s (" << Num(rtf, 3) << "x real time), " << collisions_ << " collisions\n";
    for (const Item& i : items) {
      t << "  " << std::left << std::setw(14) << i.name << std::setw(74) << i.detail << std::right << std::setw(4) << i.points
        << " / " << i.max << "\n";
    }
    t << "  " << std::left << std::setw(88) << "total" << std::right << std::setw(4) << total << " / " << max_total << "\n";
    std::cout << t.str() << std::flush;

    std::ostringstream j;
    j << "{\n  \"event\": " << JsonString(o_.event) << ",\n  \"world\": " << JsonString(ctx.source_path)
      << ",\n  \"arena\": " << JsonString(world_.name()) << ",\n  \"seed\": " << ctx.seed
      << ",\n  \"state\": " << JsonString(mission::ToString(state_)) << ",\n  \"detail\": " << JsonString(detail_)
      << ",\n  \"completed\": " << (completed ? "true" : "false") << ",\n  \"timed_out\": " << (timed_out_ ? "true" : "false")
      << ",\n  \"interrupted\": " << (interrupted ? "true" : "false") << ",\n  \"time_s\": " << Num(time_s)
      << ",\n  \"sim_seconds\": " << Num(sim_s) << ",\n  \"wall_seconds\": " << Num(wall_s) << ",\n  \"real_time_factor\": " << Num(rtf)
      << ",\n  \"collisions\": " << collisions_ << ",\n  \"start\": " << PoseJson(start) << ",\n  \"final\": " << PoseJson(final_pose);
    if (!warehouse) {  // the robot had to come back to its start
      j << ",\n  \"final_error\": {\"x_m\": " << Num(ex) << ", \"y_m\": " << Num(ey) << ", \"theta_deg\": " << Num(eth) << "}";
    }
    if (has_slam_error) {
      j << ",\n  \"slam_final_error\": {\"x_m\": " << Num(sx) << ", \"y_m\": " << Num(sy) << ", \"theta_deg\": " << Num(sth) << "}";
    }
    if (!warehouse) {
      j << ",\n  \"map\": {\"coverage\": " << Num(mq.coverage) << ", \"wall_precision\": " << Num(mq.precision)
        << ", \"reachable_cells\": " << mq.reachable_cells << ", \"occupied_cells\": " << mq.occupied_cells << "}";
    } else {
      j << ",\n  \"localized_at_s\": " << (localized_us_ >= 0 ? Num((localized_us_ - t0_us_) * 1e-6) : "null")
        << ",\n  \"levels_reached\": " << levels_reached << ",\n  \"stops\": [";
      for (size_t k = 0; k < stops_.size(); ++k) {
        j << (k ? "," : "") << "\n    {\"stop\": " << JsonString(stops_[k].Name()) << ", \"pose\": " << PoseJson(stops_[k].pose)
          << ", \"done_at_s\": " << (k < stop_done_us_.size() && stop_done_us_[k] >= 0 ? Num((stop_done_us_[k] - t0_us_) * 1e-6) : "null")
          << ", \"missed\": " << (k < stop_done_us_.size() && stop_done_us_[k] < 0 ? "true" : "false") << "}";
      }
      j << "\n  ]";
    }
    j << ",\n  \"points\": {";
    for (const Item& i : items) j << JsonString(i.name) << ": " << i.points << ", ";
    j << "\"total\": " << total << ", \"max\": " << max_total << "}\n}\n";

    const std::string dir = ctx.output_dir;
    WriteTum(dir + "/true_path.tum", truth_, Pose2D{});
    WriteTum(dir + "/slam_path.tum", slam_, frame);
    if (map_) {
      drivers::WriteBotlabMap(*map_, dir + "/final_map.map");
      const mapping::OccupancyGrid picture = CropToKnown(*map_, 0.3);
      std::vector<drivers::MapOverlay> overlays;
      std::vector<Pose2D> driven, truth, stops;
      for (const auto& p : slam_) driven.push_back(p.pose);
      const Pose2D inv = frame.Inverse();
      for (size_t i = 0; i < truth_.size(); i += 5) truth.push_back(inv.Compose(truth_[i].pose));
      for (const warehouse::Stop& st : stops_) stops.push_back(inv.Compose(st.pose));
      overlays.push_back({truth, 0, 0, 0, false, "true path"});
      overlays.push_back({driven, 31, 119, 180, false, "SLAM path"});
      if (!path_.empty()) overlays.push_back({path_, 214, 39, 40, false, "last planned path"});
      if (!stops.empty()) overlays.push_back({stops, 44, 160, 44, true, "targets and drop-offs"});
      drivers::WriteMapPngWithOverlays(picture, overlays, 4, dir + "/final_map.png");
    }
    WriteFileAtomically(dir + "/score.json", [&](std::ostream& out) { out << j.str(); });
    if (ctx.results) {
      ctx.results->insert(ctx.results->end(), {{"event", EventTitle(o_.event)}, {"arena", world_.name()}, {"seed", std::to_string(ctx.seed)},
                      {"result", result}, {"time_s", Num(time_s, 4)}, {"points", std::to_string(total)},
                      {"max_points", std::to_string(max_total)}, {"collisions", std::to_string(collisions_)},
                      {"real_time_factor", Num(rtf, 3)}});
    }
  }

 private:
  // The SLAM map is in the start frame; the true walls in the world frame.
  MapQuality Quality(const mapping::OccupancyGrid& m, const Pose2D& start) const {
    MapQuality q;
    const mapping::OccupancyGrid& truth = world_.truth();
    const std::vector<uint8_t> reach = sim::ReachableFreeMask(world_, start);
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

  // The map's known cells and `margin_m` around them (SLAM's map starts large; the picture need not).
  static mapping::OccupancyGrid CropToKnown(const mapping::OccupancyGrid& m, double margin_m) {
    int x0 = m.width(), y0 = m.height(), x1 = -1, y1 = -1;
    for (int cy = 0; cy < m.height(); ++cy) {
      for (int cx = 0; cx < m.width(); ++cx) {
        if (m.at(cx, cy) == 0) continue;
        x0 = std::min(x0, cx), x1 = std::max(x1, cx), y0 = std::min(y0, cy), y1 = std::max(y1, cy);
      }
    }
    if (x1 < 0) return m;
    const int pad = static_cast<int>(std::ceil(margin_m / m.resolution()));
    x0 = std::max(0, x0 - pad), y0 = std::max(0, y0 - pad);
    x1 = std::min(m.width() - 1, x1 + pad), y1 = std::min(m.height() - 1, y1 + pad);
    mapping::OccupancyGrid c(x1 - x0 + 1, y1 - y0 + 1, m.resolution(), m.origin_x() + x0 * m.resolution(),
                             m.origin_y() + y0 * m.resolution());
    for (int cy = y0; cy <= y1; ++cy) {
      for (int cx = x0; cx <= x1; ++cx) c.at(cx - x0, cy - y0) = m.at(cx, cy);
    }
    return c;
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

  // Warehouse: a stop is done when the true pose has stayed within the tolerances of it for the
  // dwell time. Stops are judged in order; standing at a later stop first marks the ones before it
  // missed (that delivery fails, the rest still count).
  static bool Near(const Pose2D& p, const Pose2D& goal) {
    return warehouse::AtStop(p, goal);
  }

  void JudgeStop(const TimedPose& truth) {
    const size_t next = stop_done_us_.size();  // stops before it are judged (done or missed)
    // Still standing where the last stop was done: a later stop at the same place (the drop-offs
    // repeat) must not count until the robot has left.
    if (!left_last_stop_ && next > 0 && stop_done_us_.back() >= 0) {
      left_last_stop_ = !Near(truth.pose, stops_[next - 1].pose);
      if (!left_last_stop_) return;
    }
    int at = -1;
    for (size_t k = next; k < stops_.size() && at < 0; ++k) {
      if (Near(truth.pose, stops_[k].pose)) at = static_cast<int>(k);
    }
    if (at != near_stop_) near_stop_ = at, near_since_us_ = truth.t_us;
    if (at < 0 || (truth.t_us - near_since_us_) * 1e-6 < warehouse::kDwellS) return;
    for (size_t k = next; k < static_cast<size_t>(at); ++k) {
      stop_done_us_.push_back(-1);
      mbot::log::Warn("referee: " + stops_[k].Name() + " missed");
    }
    stop_done_us_.push_back(truth.t_us);
    near_stop_ = -1;
    left_last_stop_ = false;
    mbot::log::Info("referee: " + stops_[at].Name() + " done at " + Num((truth.t_us - t0_us_) * 1e-6, 4) + " s");
  }

  RefereeOptions o_;
  Bus* bus_ = nullptr;
  sim::World world_;
  std::chrono::steady_clock::time_point wall0_;
  int64_t t0_us_ = -1, last_us_ = 0, end_us_ = -1;
  std::vector<TimedPose> truth_, slam_;
  std::shared_ptr<const mapping::OccupancyGrid> map_;
  std::vector<Pose2D> path_;
  mission::MissionState state_ = mission::MissionState::kInitializing;
  std::string detail_;
  int collisions_ = 0;
  bool stop_sent_ = false, timed_out_ = false;
  int64_t localized_us_ = -1;
  // Warehouse.
  std::vector<warehouse::Stop> stops_;
  std::vector<int64_t> stop_done_us_;  // per judged stop, in order: when it was done, -1 missed
  int near_stop_ = -1;                  // the stop the robot stands at, since near_since_us_
  bool left_last_stop_ = true;          // the robot has moved off the last stop done
  int64_t near_since_us_ = -1;
};

}  // namespace

StageType RefereeStageType() {
  return {"referee",
          "scores a competition event on the simulator (pose tiers, map quality, time, collisions), ends the run when "
          "the mission finishes or time runs out, writes score.json, trajectories and the final map",
          [](config::Section& s) -> std::unique_ptr<Stage> {
            RefereeOptions o;
            o.event = s.GetChoice("event", o.event, {"speed_run", "maze_explorer", "warehouse"}, "which event is scored");
            o.time_limit_s = s.GetDouble("time_limit_s", o.time_limit_s, "the run ends here if the mission has not [s]", 1.0, 1e5);
            o.finish_delay_s = s.GetDouble("finish_delay_s", o.finish_delay_s, "simulate this long after the mission ends [s]", 0.0, 60.0);
            o.mission_status_channel = s.GetString("mission_status_channel", o.mission_status_channel, "channel of the mission's states");
            return std::make_unique<RefereeStage>(o);
          }};
}

}  // namespace mbot::app
