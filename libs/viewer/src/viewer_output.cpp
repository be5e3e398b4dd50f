// The viewer as an output of the pipeline: every event of the run, through its own queue and
// thread, becomes Foxglove messages on the WebSocket server, and the page is served beside it.
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/msgs/stage.hpp"
#include "mbot/viewer/foxglove_encoder.hpp"
#include "mbot/viewer/server.hpp"

namespace mbot::viewer {

namespace {

class ViewerOutput : public msgs::Output {
 public:
  ViewerOutput(ServerOptions options, Frames frames, double robot_radius_m, double time_rate_hz)
      : options_(std::move(options)),
        encoder_(std::move(frames), robot_radius_m),
        time_period_us_(static_cast<int64_t>(1e6 / time_rate_hz)) {}

  void Open(const msgs::RunContext& context) override {
    msgs::Inbox* inbox = context.inbox;
    msgs::Playback* playback = context.playback;
    // The page offers pause and speed only on a recording.
    options_.metadata["playback"] = playback ? "true" : "false";
    server_ = std::make_unique<FoxgloveServer>(options_, Channels());
    // A person's goal and teleop (control on): into the run, as events the mission takes.
    server_->OnClientMessage([inbox, playback](const std::string& topic, const std::string&, const nlohmann::json& m) {
      if (topic == "/playback") {  // {"paused": bool, "speed": number}: a recording's pace
        if (!playback) throw std::invalid_argument("/playback: this run is not a recording (live or simulated)");
        const double speed = m.at("speed").get<double>();
        if (!(speed >= 0 && speed <= 1000)) throw std::invalid_argument("/playback: speed must be in [0, 1000]");
        playback->Set(speed, m.at("paused").get<bool>());
        return;
      }
      if (!inbox) return;
      msgs::Event e;
      e.channel = "viewer" + topic;
      if (topic == "/goal_pose") {  // foxglove.PoseInFrame, map frame
        const nlohmann::json& p = m.at("pose");
        const double qz = p.at("orientation").value("z", 0.0), qw = p.at("orientation").value("w", 1.0);
        e.kind = msgs::EventKind::kGoal;
        e.payload = msgs::Pose2D{p.at("position").at("x").get<double>(), p.at("position").at("y").get<double>(),
                                 2 * std::atan2(qz, qw)};
      } else if (topic == "/cmd_vel") {  // a twist: linear.x forward, angular.z turning
        e.kind = msgs::EventKind::kTeleop;
        e.payload =
            msgs::MotorCommand::Velocity(m.at("linear").at("x").get<double>(), m.at("angular").at("z").get<double>());
      } else if (topic ==
                 "/slam_control") {  // {"mapping": bool, "localization": bool, "clear_map": bool}, each optional
        msgs::SlamControl c;
        if (m.contains("mapping")) c.mapping = m.at("mapping").get<bool>();
        if (m.contains("localization")) c.localization = m.at("localization").get<bool>();
        c.clear_map = m.value("clear_map", false);
        e.kind = msgs::EventKind::kSlamControl;
        e.payload = c;
      } else {
        throw std::invalid_argument("the viewer takes /goal_pose, /cmd_vel, /slam_control and /playback, not " + topic);
      }
      inbox->Post(std::move(e));
    });
    server_->Start();
    const ServerOptions& o = server_->options();
    const std::string query = o.token.empty() ? "" : "/?token=" + o.token;
    std::string where = "viewer: Foxglove at ws://" + o.address + ":" + std::to_string(server_->port()) + query;
    if (server_->http_port() >= 0) {
      where += ", the page at http://" + o.address + ":" + std::to_string(server_->http_port()) + query;
    }
    log::Info(where + (o.control ? " (control on: goals and teleop accepted)" : ""));
  }

  void Send(const msgs::Event& event) override { SendOffered(event, -1); }

  void SendOffered(const msgs::Event& event, int64_t offered_wall_us) override {
    if (!server_) return;
    for (FoxgloveMessage& m : encoder_.Encode(event)) {
      server_->Publish(m.topic, m.t_us, m.payload.dump());
      // After each scan, when the pipeline offered it (wall clock): the page shows how late it is.
      if (m.topic == "/scan" && offered_wall_us >= 0) {
        server_->Publish(
            "/scan_stamp", m.t_us,
            nlohmann::json{{"timestamp", TimeJson(m.t_us)}, {"topic", "/scan"}, {"offered_wall_us", offered_wall_us}}
                .dump());
      }
    }
    if (event.t_us >= last_time_us_ + time_period_us_ || event.t_us < last_time_us_) {
      server_->PublishTime(event.t_us);
      last_time_us_ = event.t_us;
    }
  }

  void Close(bool /*interrupted*/) override {
    if (!server_) return;
    const ServerStats s = server_->Stats();
    server_->Stop();
    long long messages = 0, bytes = 0;
    for (const auto& [topic, n] : s.messages_by_topic) messages += n;
    for (const auto& [topic, n] : s.bytes_by_topic) bytes += n;
    log::Info("viewer: " + std::to_string(s.connections) + " connections (" + std::to_string(s.refused) +
              " refused), " + std::to_string(messages) + " messages, " + std::to_string(bytes / 1024) + " KiB sent; " +
              std::to_string(s.dropped_slow) + " dropped for slow clients, " +
              std::to_string(s.closed_slow + s.closed_abusive) + " clients closed");
  }

 private:
  ServerOptions options_;
  std::unique_ptr<FoxgloveServer> server_;  // made at Open: its serverInfo says what the run offers
  FoxgloveEncoder encoder_;
  int64_t time_period_us_;
  int64_t last_time_us_ = -(int64_t{1} << 62);
};

std::unique_ptr<msgs::Output> CreateViewer(config::Section& s) {
  ServerOptions o;
  o.address = s.GetString("address", o.address,
                          "address the servers bind (127.0.0.1: this machine only; any other needs a token)");
  o.port = static_cast<int>(s.GetInt("port", o.port, "the Foxglove WebSocket port (0: any free port)", 0, 65535));
  o.http_port = static_cast<int>(
      s.GetInt("http_port", o.http_port, "the page's HTTP port (0: any free port, -1: no page)", -1, 65535));
  o.token = s.GetString("token", "",
                        "the token every client must give (?token=...); generated and printed when the address is "
                        "not loopback or control is on");
  o.control = s.GetBool("control", false, "clients may publish a goal and teleop (needs a token)");
  o.allowed_origins =
      s.GetList("allowed_origins", {}, "browser origins allowed besides the page's own and https://app.foxglove.dev");
  o.max_clients = static_cast<int>(s.GetInt("max_clients", o.max_clients, "connected viewers at most", 1, 1024));
  o.max_client_message_bytes =
      static_cast<size_t>(s.GetInt("max_client_message_bytes", static_cast<long long>(o.max_client_message_bytes),
                                   "largest message a client may send", 256, 16 << 20));
  o.max_client_backlog_bytes =
      static_cast<size_t>(s.GetInt("max_client_backlog_bytes", static_cast<long long>(o.max_client_backlog_bytes),
                                   "unsent bytes past which a client's messages are dropped", 4096, 1LL << 30));
  o.stalled_client_timeout_s = s.GetDouble("stalled_client_timeout_s", o.stalled_client_timeout_s,
                                           "a client that reads nothing this long is closed", 0.1, 3600);
  Frames frames;
  frames.map = s.GetString("map_frame", frames.map, "the map's frame");
  frames.odom = s.GetString("odom_frame", frames.odom, "the odometry's frame");
  frames.base = s.GetString("base_frame", frames.base, "the robot's frame");
  frames.lidar = s.GetString("lidar_frame", frames.lidar, "the lidar's frame");
  const double radius = s.GetDouble("robot_radius_m", 0.1, "the footprint drawn for the robot", 0.01, 5);
  const double time_hz = s.GetDouble("time_rate_hz", 10, "how often the data's clock is sent", 0.1, 1000);
  if ((!IsLoopback(o.address) || o.control) && o.token.empty()) o.token = NewToken();
  return std::make_unique<ViewerOutput>(std::move(o), std::move(frames), radius, time_hz);
}

}  // namespace

void RegisterViewer() {
  msgs::RegisterOutputType({"viewer",
                            "the live view: a Foxglove WebSocket server (Foxglove, Lichtblick) and the project's page "
                            "in the browser; also [viewer] enabled = true on any config",
                            CreateViewer, false,
                            "map:2, particles:5, lidar:10, odometry:20, pose_estimate:20, crates:5, tag_sightings:10, "
                            "frontiers:2, obstacle_distance:1, score:2"});
}

}  // namespace mbot::viewer
