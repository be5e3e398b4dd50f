#include "mbot/ros2/ros2_transport.hpp"

#include <cstring>
#include <filesystem>
#include <fstream>

#include "bag_recorder.hpp"
#include "bag_source.hpp"
#include "ros2_live.hpp"
#include "mbot/common/config.hpp"
#include "mbot/msgs/source.hpp"

namespace mbot::ros2 {

namespace topics = msgs::topics;

msgs::TopicTable DefaultTopics() {
  return msgs::TopicTable({{topics::kLidar, "/scan"},
                           {topics::kOdometry, "/odom"},
                           {topics::kImu, "/imu"},
                           {topics::kVelocityCommand, "/cmd_vel"},
                           {topics::kEncoders, "/encoders"},
                           {topics::kMotorVelocity, "/motor_vel"},
                           {topics::kSlamMap, "/map"},
                           {topics::kSlamPose, "/estimated_pose"},
                           {topics::kSlamParticles, "/particle_cloud"},
                           {topics::kPath, "/planned_path"},
                           {topics::kFrontiers, "/frontier_markers"},
                           {topics::kMissionStatus, "/mission_state"},
                           {topics::kTags, "/detections"},
                           {topics::kTruePose, "/ground_truth"}});
}

namespace {

// A .mcap file (its magic bytes), or a rosbag2 folder holding one.
bool IsMcapBag(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  std::string file = path;
  if (fs::is_directory(path, ec)) {
    try {
      file = BagFiles(path).front();
    } catch (const std::exception&) {
      return false;
    }
  }
  std::ifstream in(file, std::ios::binary);
  char head[8] = {};
  in.read(head, 8);
  return in.gcount() == 8 && std::memcmp(head, "\x89MCAP0\r\n", 8) == 0;
}

bool IsRos1Bag(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[13] = {};
  in.read(head, 13);
  return in.gcount() == 13 && std::memcmp(head, "#ROSBAG V2.0\n", 13) == 0;
}

void ParseBagOptions(config::Section& s, msgs::SourceOptions* o) {
  ParseChannelRoles(s, &o->roles);
  BagSourceOptions b;
  b.topics.Parse(s, "topics");
  b.robot_frame = s.GetString("robot_frame", b.robot_frame,
                              "mcap: the robot's frame, whose transform to the scan's frame (/tf_static) is the "
                              "lidar's mount ('' = the frame /odom moves, else base_footprint)");
  b.reorder_window_us = static_cast<int64_t>(
      1e6 * s.GetDouble("reorder_window_s", b.reorder_window_us * 1e-6,
                        "mcap: messages are re-sorted by log time within this window [s]", 0.0, 10.0));
  o->extra = b;
}

}  // namespace

void RegisterRos2Transport() {
  if (msgs::FindSourceType("mcap")) return;
  msgs::RegisterSourceType({"mcap",
                            "a ROS 2 bag (rosbag2 with storage mcap: its folder or a .mcap file), or any MCAP file of "
                            "ROS 2 messages; topics map to the pipeline's by `topics`, messages to events by type",
                            IsMcapBag,
                            -1,  // before the file types: a bag may be a folder
                            ParseBagOptions,
                            [](const msgs::SourceOptions& o) { return std::make_unique<McapBagSource>(o); },
                            msgs::SourceType::Path::kFileOrFolder});
  msgs::RegisterSourceType({"ros1_bag",
                            "a ROS 1 bag (format 2.0; chunks plain, bz2 or lz4), as most public 2D SLAM data ships: "
                            "the same topics and keys as mcap",
                            IsRos1Bag, 10, ParseBagOptions,
                            [](const msgs::SourceOptions& o) { return std::make_unique<McapBagSource>(o); }});
  msgs::SourceType live{
      "ros2_live",
      "a ROS 2 robot (or the simulated one, sim_robot_ros2.ini) over DDS, in wall-clock time; url "
      "is dds:<ROS_DOMAIN_ID>; topics, frames and QoS are the MBot's unless `topics` says otherwise",
      nullptr,
      0,
      [](config::Section& s, msgs::SourceOptions* o) {
        ParseChannelRoles(s, &o->roles);
        Ros2LiveOptions r;
        r.node = ParseRos2NodeOptions(s, "dds:0", "mbot_nav", true);
        msgs::LiveSourceOptions d;
        d.channels = {msgs::topics::kLidar, msgs::topics::kOdometry, msgs::topics::kImu, msgs::topics::kEncoders};
        r.live = msgs::ParseLiveSourceOptions(s, "ros2_live", d);
        r.reset_odometry_service = s.GetString(
            "reset_odometry_service", "",
            "ros2_live: a std_srvs/Trigger service called once at start to zero the robot's odometry (the MBot's "
            "/reset_odometry; '' = none)");
        o->extra = r;
      },
      OpenRos2Live};
  live.path_kind = msgs::SourceType::Path::kUnchecked;
  live.default_url = "dds:0";
  msgs::RegisterSourceType(std::move(live));
  msgs::RegisterStageType(Ros2BridgeStageType());
  msgs::RegisterOutputType(Ros2OutputType());
  msgs::OutputType recorder;
  recorder.name = "rosbag2";
  recorder.doc =
      "records the run as a ROS 2 bag (rosbag2, storage mcap: run.mcap and metadata.yaml in the output folder) that "
      "Foxglove, rosbags and ros2 bag open";
  recorder.create = [](config::Section& s) -> std::unique_ptr<msgs::Output> {
    return std::make_unique<BagRecorder>(ParseBagRecorderOptions(s));
  };
  recorder.wait_when_full = true;  // a recorder loses nothing
  msgs::RegisterOutputType(std::move(recorder));
}

}  // namespace mbot::ros2
