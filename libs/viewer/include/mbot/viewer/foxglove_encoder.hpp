// The run's events as Foxglove messages: JSON payloads that follow Foxglove's own schemas
// (foxglove.Grid, foxglove.LaserScan, foxglove.FrameTransforms, foxglove.PosesInFrame,
// foxglove.PoseInFrame, foxglove.SceneUpdate, foxglove.Log) and two of the project's (the mission's
// and SLAM's state). Pure: no socket, no thread; the server (server.hpp) sends what this returns.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mbot/msgs/events.hpp"
#include "mbot/msgs/visitor.hpp"

namespace mbot::viewer {

// The frames the transforms connect: map → odom → base_link → lidar (ROS's REP 105 names).
struct Frames {
  std::string map = "map";
  std::string odom = "odom";
  std::string base = "base_link";
  std::string lidar = "lidar";
};

// One channel the viewer offers: its topic, the schema's name and text (JSON Schema).
struct ChannelSpec {
  std::string topic;
  std::string schema_name;
  std::string schema;
};

// Every channel, in the order the server advertises them. Topics are fixed names (/map, /scan, /tf,
// /pose, /particles, /path, /scene, /log, /mission, /slam_status, /odom,
// /obstacle_distance, /score).
const std::vector<ChannelSpec>& Channels();

struct FoxgloveMessage {
  std::string topic;
  int64_t t_us = 0;  // the data's clock (the event's time)
  nlohmann::json payload;
};

// Turns events into messages; remembers the latest odometry, pose estimate and lidar mount so the
// transforms and the robot's footprint are whole in every message.
class FoxgloveEncoder : public msgs::EventVisitor {
 public:
  explicit FoxgloveEncoder(Frames frames = {}, double robot_radius_m = 0.1);

  // The messages an event becomes (none for kinds the viewer does not show).
  std::vector<FoxgloveMessage> Encode(const msgs::Event& event);

  bool Lidar(const msgs::Event& e, const msgs::LidarScan& scan) override;
  bool Pose(const msgs::Event& e, const msgs::Pose2D& pose) override;
  bool Map(const msgs::Event& e, const msgs::OccupancyGrid& grid) override;
  bool PathPoses(const msgs::Event& e, const msgs::Path& path) override;
  bool Slam(const msgs::Event& e, const msgs::SlamStatus& status) override;
  bool Mission(const msgs::Event& e, const msgs::MissionStatus& status) override;
  bool ParticleSet(const msgs::Event& e, const msgs::Particles& particles) override;
  bool Tags(const msgs::Event& e, const msgs::TagSightings& tags) override;
  bool Crates(const msgs::Event& e, const msgs::CrateStates& crates) override;
  bool FrontierSet(const msgs::Event& e, const msgs::Frontiers& frontiers) override;
  bool Distances(const msgs::Event& e, const msgs::DistanceGrid& distances) override;
  bool Score(const msgs::Event& e, const msgs::ScoreStatus& score) override;

 private:
  void Add(const std::string& topic, int64_t t_us, nlohmann::json payload);
  void AddTransforms(int64_t t_us);

  Frames frames_;
  double robot_radius_m_;
  std::optional<msgs::Pose2D> odom_, estimate_;
  msgs::Pose2D lidar_mount_;
  std::vector<FoxgloveMessage> out_;
};

// Building blocks, public for the tests.
nlohmann::json TimeJson(int64_t t_us);                     // foxglove.Time {sec, nsec}
nlohmann::json PoseJson(const msgs::Pose2D& p, double z);  // foxglove.Pose
std::string Base64(const void* data, size_t size);
// A log-odds cell as ROS's occupancy (-1 unknown, 0 free … 100 occupied), what Foxglove and the
// page colour.
int8_t OccupancyPercent(int8_t log_odds);

}  // namespace mbot::viewer
