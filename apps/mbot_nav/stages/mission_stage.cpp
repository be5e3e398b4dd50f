// `mission`: the adapter between the event stream and mission::Mission (libs/mission), the robot's
// autonomy after SLAM. It hands the mission SLAM's poses, maps and states and, on every odometry
// message (the firmware's 50 Hz), publishes what the mission asks: its state, its paths and the
// velocity command on MBOT_VEL_CMD (to the simulator, or to a robot over LCM). It does nothing
// harmful on a log (nobody listens to its commands there). Writes mission.json.
#include <optional>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/config.hpp"
#include "mbot/drivers/map_io.hpp"
#include "mbot/mission/mission.hpp"
#include "mbot/mission/mission_config.hpp"
#include "mbot/vision/tag_observer.hpp"
#include "mbot/vision/vision_config.hpp"
#include "report.hpp"
#include "mbot/msgs/topics.hpp"
#include "mbot/reports/mission_report.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

using msgs::Event;
using msgs::EventKind;

struct MissionStageOptions {
  mission::MissionOptions mission;
  std::string status_channel = msgs::topics::kMissionStatus;
  std::string path_channel = msgs::topics::kPath;  // follow: paths sent by a GUI arrive here
  std::string command_channel = msgs::topics::kVelocityCommand;
  std::string fork_channel = msgs::topics::kForkliftCommand;  // heavy_lift: the tines' target height
  vision::CameraMount camera;                                 // heavy_lift: where the tags' camera sits on the robot
  double status_every_s = 0.0;  // also repeat the last state this often (a lossy link); 0: on change only
};

class MissionStage : public Stage {
 public:
  explicit MissionStage(MissionStageOptions o) : o_(std::move(o)) {}

  void Start(const RunContext& ctx) override {
    bus_ = ctx.bus;
    mission_ = std::make_unique<mission::Mission>(o_.mission, ctx.seed);
    mission_->set_watched(bus_ && bus_->Watched());
  }

  void OnEvent(const Event& ev) override {
    switch (ev.kind) {
      case EventKind::kPoseEstimate: return mission_->OnPoseEstimate(ev.t_us, std::get<motion::Pose2D>(ev.payload));
      case EventKind::kMap: return mission_->OnMap(std::get<std::shared_ptr<const mapping::OccupancyGrid>>(ev.payload));
      case EventKind::kSlamStatus: return mission_->OnSlamState(std::get<mapping::SlamStatus>(ev.payload).state);
      case EventKind::kPath:
        if (ev.channel == o_.path_channel) mission_->OnPath(std::get<msgs::Path>(ev.payload).poses);
        return;
      case EventKind::kTagSightings: {
        std::vector<mission::TagSeen> seen;
        for (const msgs::TagSighting& t : std::get<msgs::TagSightings>(ev.payload).tags) {
          const vision::TagOnRobot r =
              vision::TagInRobotFrame(o_.camera, {t.x_m, t.y_m, t.z_m}, {t.qw, t.qx, t.qy, t.qz});
          seen.push_back({t.id, r.position[0], r.position[1], r.position[2], r.facing_rad});
        }
        return mission_->OnTags(ev.t_us, seen);
      }
      case EventKind::kGoal:  // a person's goal (the viewer)
        if (const auto* g = std::get_if<motion::Pose2D>(&ev.payload)) mission_->OnGoal(*g);
        return;
      case EventKind::kTeleop:  // a person driving (the viewer's keys)
        if (const auto* c = std::get_if<msgs::MotorCommand>(&ev.payload)) {
          mission_->OnTeleop(ev.t_us, c->velocity.v_m_s, c->velocity.w_rad_s);
        }
        return;
      case EventKind::kForkliftStatus: {
        const auto& f = std::get<msgs::ForkliftStatus>(ev.payload);
        return mission_->OnForklift({f.height_m, f.target_m, f.crate_id, f.carrying});
      }
      case EventKind::kOdometry:
        for (const mission::MissionOutput& out :
             mission_->OnOdometry(ev.t_us, std::get<motion::Pose2D>(ev.payload), ev.stamp_us)) {
          Publish(ev.t_us, out);
        }
        RepeatStatus(ev.t_us);
        return;
      default: return;
    }
  }

  void Finish(const RunContext& ctx, bool interrupted) override {
    const mission::MissionReport r = mission_->Report();
    const bool explored = r.task == mission::TaskKind::kExplore || o_.mission.explore_first;
    reports::WriteJson(ctx.output_dir + "/mission.json", reports::MissionJson(r, interrupted, explored));
    if ((r.task == mission::TaskKind::kExplore || o_.mission.explore_first) && mission_->map()) {
      // What the frontier detection saw in the last map: faint cells, frontier cells, the frontiers left.
      const auto& frontier = o_.mission.exploration.frontier;
      const planning::FrontierLayers layers = planning::ComputeFrontierLayers(*mission_->map(), frontier);
      std::vector<motion::Pose2D> left;
      for (const planning::FrontierLeft& f : r.frontiers_left) left.push_back({f.x, f.y, 0.0});
      const std::string t = " (" + std::to_string(frontier.free_threshold) + " < log-odds < " +
                            std::to_string(frontier.occupied_threshold) + ")";
      drivers::WriteMapPngWithOverlays(mapping::CropToKnown(*mission_->map(), 0.3),
                                       {{layers.faint, 120, 170, 230, true, "seen too faintly to count" + t},
                                        {layers.frontier, 240, 140, 0, true, "frontier cells"},
                                        {left, 214, 39, 40, true, "frontiers left at the end"}},
                                       4, ctx.output_dir + "/frontiers.png");
    }
  }

 private:
  void Publish(int64_t t_us, const mission::MissionOutput& out) {
    if (!bus_) return;
    if (const auto* s = std::get_if<mission::MissionStatus>(&out)) {
      bus_->Emit(this, Event{t_us, t_us, o_.status_channel, EventKind::kMissionStatus, *s});
      last_status_ = *s;
      last_status_us_ = t_us;
    } else if (const auto* p = std::get_if<mission::PathOut>(&out)) {
      bus_->Emit(this, Event{t_us, t_us, o_.path_channel, EventKind::kPath, msgs::Path{p->poses}});
    } else if (const auto* x = std::get_if<mission::ExplorationOut>(&out)) {
      bus_->Emit(this, Event{t_us, t_us, msgs::topics::kFrontiers, EventKind::kFrontiers, x->frontiers});
      if (x->distances) {
        bus_->Emit(this, Event{t_us, t_us, msgs::topics::kObstacleDistance, EventKind::kObstacleDistance,
                               std::shared_ptr<const msgs::DistanceGrid>(x->distances)});
      }
    } else if (const auto* f = std::get_if<mission::ForkOut>(&out)) {
      bus_->Emit(this,
                 Event{t_us, t_us, o_.fork_channel, EventKind::kForkliftCommand, msgs::ForkliftCommand{f->height_m}});
    } else {
      const auto& c = std::get<motion::VelocityCommand>(out);
      bus_->Emit(this, Event{t_us, t_us, o_.command_channel, EventKind::kMotorCommand,
                             msgs::MotorCommand::Velocity(c.v_m_s, c.w_rad_s)});
    }
  }

  // Over a lossy link a state sent once can be lost ("completed" above all): repeat the last one.
  void RepeatStatus(int64_t t_us) {
    if (o_.status_every_s <= 0 || !last_status_ || !bus_) return;
    if (t_us - last_status_us_ < static_cast<int64_t>(o_.status_every_s * 1e6)) return;
    last_status_us_ = t_us;
    bus_->Emit(this, Event{t_us, t_us, o_.status_channel, EventKind::kMissionStatus, *last_status_});
  }

  MissionStageOptions o_;
  std::unique_ptr<mission::Mission> mission_;
  Bus* bus_ = nullptr;
  std::optional<mission::MissionStatus> last_status_;
  int64_t last_status_us_ = 0;
};

}  // namespace

static StageType MissionStageType() {
  return {"mission",
          "the autonomy after SLAM (libs/mission): drives a circuit of waypoints, explores and returns home, makes the "
          "Warehouse's deliveries, follows a GUI's paths or stacks crates by their tags (Heavy Lift); emits velocity "
          "commands, forklift commands, paths and states",
          [](config::Section& s) -> std::unique_ptr<Stage> {
            MissionStageOptions o;
            o.mission = mission::ParseMissionOptions(s);
            o.status_channel = s.GetString("status_channel", o.status_channel, "channel of the status events");
            o.path_channel = s.GetString("path_channel", o.path_channel,
                                         "paths go out here; with task = follow, a GUI's paths come in here");
            o.command_channel = s.GetString("command_channel", o.command_channel, "velocity commands go out here");
            o.fork_channel =
                s.GetString("fork_channel", o.fork_channel, "heavy_lift: the forklift's target heights go out here");
            o.camera = vision::ParseCameraMount(s, o.camera);
            o.status_every_s = s.GetDouble("status_every_s", o.status_every_s,
                                           "also repeat the last state this often, for a lossy link (0: only on "
                                           "change) [s]",
                                           0.0, 3600.0);
            return std::make_unique<MissionStage>(o);
          }};
}

const RegisterStage kMissionRegistered{MissionStageType()};

}  // namespace mbot::app
