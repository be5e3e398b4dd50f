// `exploration`: runs the exploration state machine on the stream's maps and poses (a replayed
// SLAM_MAP + SLAM_POSE, the simulator, a live robot) and records what it decided: every state
// change and every new path, written to output.dir as JSON. It drives nothing itself.
#include <iostream>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/planning/exploration.hpp"
#include "mbot/planning/planning_config.hpp"
#include "mbot/reports/json.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

struct ExplorationStageOptions {
  planning::ExplorationOptions exploration;
  msgs::EventKind pose_kind = msgs::EventKind::kReferencePose;
  double update_period_s = 0.5;  // at most one explorer update per this much data time
  std::string json_file = "exploration.json";
};

struct Decision {
  double t_s;
  std::string state, reason;
  std::vector<motion::Pose2D> path;
};

class ExplorationStage : public Stage {
 public:
  explicit ExplorationStage(ExplorationStageOptions o) : options_(std::move(o)), explorer_(options_.exploration) {}

  void OnEvent(const msgs::Event& ev) override {
    if (ev.kind == msgs::EventKind::kMap) {
      map_ = std::get<std::shared_ptr<const mapping::OccupancyGrid>>(ev.payload);
    } else if (ev.kind == options_.pose_kind) {
      pose_ = std::get<motion::Pose2D>(ev.payload);
      has_pose_ = true;
    } else {
      return;
    }
    if (!map_ || !has_pose_) return;
    const double t = ev.t_us * 1e-6;
    if (updates_ > 0 && t - last_update_s_ < options_.update_period_s) return;
    last_update_s_ = t;
    ++updates_;
    const planning::ExplorationUpdate u = explorer_.Update(*map_, pose_, t);
    if (u.new_path || u.state != last_state_) {
      decisions_.push_back({t, planning::ToString(u.state), u.reason, u.path});
      last_state_ = u.state;
    }
  }

  void Finish(const RunContext& ctx, bool interrupted) override {
    const std::string path = ctx.output_dir + "/" + options_.json_file;
    reports::Json decisions = reports::Json::array();
    for (const Decision& d : decisions_) {
      reports::Json poses = reports::Json::array();
      for (const motion::Pose2D& p : d.path) {
        poses.push_back({reports::Number(p.x), reports::Number(p.y), reports::Number(p.theta)});
      }
      decisions.push_back(
          {{"t", reports::Number(d.t_s, 12)}, {"state", d.state}, {"reason", d.reason}, {"path", std::move(poses)}});
    }
    reports::WriteJson(path, {{"final_state", planning::ToString(explorer_.state())},
                              {"failure_reason", explorer_.failure_reason()},
                              {"updates", updates_},
                              {"interrupted", interrupted},
                              {"decisions", std::move(decisions)}});
    std::cout << "exploration: " << updates_ << " updates, " << decisions_.size() << " decisions, final state "
              << planning::ToString(explorer_.state())
              << (explorer_.failure_reason().empty() ? "" : " (" + explorer_.failure_reason() + ")") << "\n";
    mbot::log::Info("wrote " + path);
  }

 private:
  ExplorationStageOptions options_;
  planning::Explorer explorer_;
  std::shared_ptr<const mapping::OccupancyGrid> map_;
  motion::Pose2D pose_;
  bool has_pose_ = false;
  int updates_ = 0;
  double last_update_s_ = 0.0;
  planning::ExplorationState last_state_ = planning::ExplorationState::kInitializing;
  std::vector<Decision> decisions_;
};

}  // namespace

static StageType ExplorationStageType() {
  return {"exploration",
          "runs the frontier-exploration state machine on the stream's maps and poses and records its paths and states",
          [](config::Section& s) -> std::unique_ptr<Stage> {
            ExplorationStageOptions o;
            const std::string pose =
                s.GetChoice("pose", "reference_pose", {"reference_pose", "ground_truth", "odometry"},
                            "which pose stream is the robot's pose (SLAM output is reference_pose)");
            o.pose_kind = pose == "ground_truth" ? msgs::EventKind::kGroundTruth
                          : pose == "odometry"   ? msgs::EventKind::kOdometry
                                                 : msgs::EventKind::kReferencePose;
            o.update_period_s = s.GetDouble("update_period_s", o.update_period_s,
                                            "at most one explorer update per this much data time [s]", 0.0, 3600.0);
            o.json_file = s.GetString("json_file", o.json_file, "decision log in output.dir");
            o.exploration = planning::ParseExplorationOptions(s);
            return std::make_unique<ExplorationStage>(o);
          }};
}

const RegisterStage kExplorationRegistered{ExplorationStageType()};

}  // namespace mbot::app
