// `lcm_bridge`: puts this pipeline on the LCM bus from the robot's side. Every event it sees on a
// `publish` channel goes out as the botlab's message (the simulated robot publishes what the Pico
// firmware and the lidar driver publish); messages arriving on `subscribe` channels (MBOT_VEL_CMD
// from the autonomy, and what the autonomy publishes for a referee to score) come in validated and
// are emitted to the later stages and the sink (the simulator, which drives its robot with them),
// stamped with the time of the event being processed. So `mbot_nav --config config/sim_robot.ini`
// is a robot an autonomy process cannot tell from a real one.
#include <set>

#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/lcm/lcm_live.hpp"
#include "mbot/msgs/loop_latency.hpp"
#include "mbot/msgs/stage.hpp"
#include "mbot/msgs/topics.hpp"

namespace mbot::lcmio {

using namespace msgs;  // the event vocabulary

namespace {

struct BridgeOptions {
  std::string url = kDefaultLcmUrl;
  std::vector<std::string> publish = {topics::kLidar, topics::kOdometry, topics::kEncoders,
                                      topics::kImu,   topics::kMotorPwm, topics::kMotorVelocity};
  std::vector<std::string> subscribe = {topics::kVelocityCommand};
};

class LcmBridgeStage : public Stage {
 public:
  explicit LcmBridgeStage(BridgeOptions o) : o_(std::move(o)), publish_(o_.publish.begin(), o_.publish.end()) {}

  void Start(const RunContext& ctx) override {
    bus_ = ctx.bus;
    ChannelRoles roles;
    roles.reference_pose.clear();  // SLAM_POSE coming back is the stack's estimate, not a reference
    roles.pose_estimate = {topics::kSlamPose};
    node_ = std::make_unique<LcmNode>(o_.url, o_.subscribe, roles);
    mbot::log::Info("lcm_bridge: publishing " + std::to_string(publish_.size()) + " channels on " + o_.url);
  }

  void OnEvent(const Event& ev) override {
    if (publish_.count(ev.channel) && node_->Publish(ev) && ev.kind == EventKind::kLidar)
      latency_.ScanSent(WallClockUs());
    std::vector<Event> got;
    node_->Poll(0, &got);
    for (Event& in : got) {
      if (in.kind == EventKind::kMotorCommand) latency_.CommandReceived(in.t_us);
      in.t_us = ev.t_us;  // into this pipeline's (the simulation's) time
      if (bus_) bus_->Emit(this, in);
    }
  }

  void Finish(const RunContext& ctx, bool /*interrupted*/) override {
    if (!node_) return;
    if (const std::string l = latency_.Summary(); !l.empty()) {
      mbot::log::Info("lcm_bridge: scan out → command back: " + l);
      latency_.WriteJson(ctx.output_dir + "/loop_latency.json", "lcm");
    }
    std::string counts;
    for (const auto& [channel, s] : node_->stats()) {
      counts += (counts.empty() ? "" : ", ") + channel + " " + std::to_string(s.received) + " in / " +
                std::to_string(s.published) + " out" +
                (s.rejected + s.unknown ? " / " + std::to_string(s.rejected + s.unknown) + " rejected" : "");
    }
    mbot::log::Info("lcm_bridge: " + counts);
  }

 private:
  BridgeOptions o_;
  std::set<std::string> publish_;
  Bus* bus_ = nullptr;
  std::unique_ptr<LcmNode> node_;
  LoopLatency latency_;
};

}  // namespace

StageType LcmBridgeStageType() {
  return {
      "lcm_bridge",
      "the robot's side of the LCM bus: publishes the events it sees on `publish` channels as the botlab's messages, "
      "and emits the validated messages arriving on `subscribe` channels (velocity commands to the simulator)",
      [](config::Section& s) -> std::unique_ptr<Stage> {
        BridgeOptions o;
        o.url = s.GetString("url", o.url, "the LCM URL (ttl=0 keeps the traffic on this machine)");
        o.publish =
            s.GetList("publish", o.publish, "channels published (what the robot's firmware and lidar driver publish)");
        o.subscribe = s.GetList("subscribe", o.subscribe, "channels listened to (the autonomy's commands and outputs)");
        return std::make_unique<LcmBridgeStage>(o);
      }};
}

}  // namespace mbot::lcmio
