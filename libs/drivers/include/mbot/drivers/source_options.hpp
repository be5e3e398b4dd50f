// [source]: which dataset to read and how to interpret its channels.
#pragma once

#include <any>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "mbot/drivers/lcm_relay.hpp"
#include "mbot/drivers/source.hpp"

namespace mbot::config {
class Section;
}

namespace mbot::drivers {

// How channel names map to roles. Pose-typed messages (pose_xyt_t, odometry_t, pose2D_t share one
// layout) get their meaning from the channel they arrive on.
struct ChannelRoles {
  std::vector<std::string> odometry = {"ODOMETRY", "MBOT_ODOMETRY"};
  std::vector<std::string> ground_truth = {"TRUE_POSE", "GROUND_TRUTH_POSE"};
  // Ground-truth channels re-zeroed as the botlab README says: subtract the first pose, rotate by -θ0.
  std::vector<std::string> rezero_ground_truth = {"GROUND_TRUTH_POSE"};
  std::vector<std::string> reference_pose = {"SLAM_POSE"};
  std::vector<std::string> velocity_command = {"MBOT_VEL_CMD"};
};

// [source] type = camera: frames from a camera (path = a device index), a video file or a
// GStreamer pipeline (OpenCV's VideoCapture), or an image folder or file replayed at `fps`.
struct CameraSourceOptions {
  double fps = 15.0;  // replay: frames are stamped 1/fps apart; a device is asked for this rate
  int width = 640;    // a device is asked for this size
  int height = 480;
  double timeout_s = 2.0;  // a device that delivers no frame for this long ends the stream (reported)
  std::string channel = "CAMERA";
};

// [source] type = lcm_live: a robot (or the simulated one) on the LCM bus, in wall-clock time.
struct LiveSourceOptions {
  // The robot's channels the autonomy listens to (current mbot_lcm_msgs names).
  std::vector<std::string> channels = {"LIDAR",         "MBOT_ODOMETRY",   "MBOT_ENCODERS",    "MBOT_IMU",
                                       "MBOT_TIMESYNC", "CONTROLLER_PATH", "MBOT_SYSTEM_RESET"};
  double duration_s = 0.0;           // 0: until Ctrl-C or a stage ends the run
  double end_after_silence_s = 0.0;  // > 0: the run ends when nothing arrived for this long
  // A watched channel silent this long is reported and the robot stopped (zero velocity published,
  // commands held back) until it is back.
  double stale_sensor_s = 1.0;
  std::vector<std::string> watched = {"LIDAR", "MBOT_ODOMETRY"};
  std::string command_channel = "MBOT_VEL_CMD";
  double report_every_s = 10.0;  // a line with the loop rate and latency this often (0: never)
};

struct SourceOptions {
  std::string type = "auto";  // a registered source type (SourceTypes()), or auto
  std::string path;           // required; for sim, the world file; for lcm_live, the LCM URL
  ChannelRoles roles;
  // CARMEN logs with old FLASER lines give no range limit; beams at or beyond it are no-returns.
  double carmen_max_range_m = 81.0;
  // CARMEN records in the order of their stamps (stamp), or in the file's order (file) for logs whose
  // stamps are arrival times that run backwards (the raw Intel log): each record's event time is then
  // its stamp held non-decreasing along the file, and its stamp is kept as the message's own.
  bool carmen_file_order = false;
  // LCM log records are re-sorted by event time within this window (lcm-logger writes them in
  // arrival order, which can run a few ms backwards).
  int64_t reorder_window_us = 100000;
  // Seed of the source's randomness, e.g. the simulator's noise ([pipeline] seed, copied here by
  // the pipeline; not a [source] key).
  uint64_t seed = 1;
  LiveSourceOptions live;      // read only when type = lcm_live
  CameraSourceOptions camera;  // read only when type = camera
  RelayOptions relay;          // read only when type = lcm_relay (path is then its robot_url)
  double relay_duration_s = 0.0;
  // The options of a source type registered by another library (the simulator's SimSourceOptions),
  // filled by that type's `parse`.
  std::any extra;
};

// A source type, registered by name like the stage types: what it reads, how its files are
// recognised (type = auto), its own keys of [source], and how it opens. libs/drivers registers
// the dataset and LCM types itself; another library registers its own (libs/sim: sim).
struct SourceType {
  std::string name;  // the [source] type value
  std::string doc;
  // True when `path` is this type's input (type = auto). Types are asked in order of
  // `detect_order` (extension checks before content sniffing), then of registration. May be empty.
  std::function<bool(const std::string& path)> detect;
  int detect_order = 0;
  // Reads the type's own keys of [source] into `options` (documents them in describe mode). May be
  // empty when the type has none beyond the common ones.
  std::function<void(config::Section& section, SourceOptions* options)> parse;
  // Opens the input. Throws std::runtime_error naming the path when it cannot be read.
  std::function<std::unique_ptr<Source>(const SourceOptions& options)> open;
};

// Adds a type; a second type of the same name is an error (std::logic_error).
void RegisterSourceType(SourceType type);
// Every registered type, libs/drivers' own first, in registration order (pointers to them stay
// valid when more are registered).
const std::deque<SourceType>& SourceTypes();
// nullptr when no type has that name.
const SourceType* FindSourceType(const std::string& name);

// Reads [source]: the common keys, then the chosen type's own (with type = auto, the type detected
// from the path when it exists). Throws config::ConfigError naming the key on bad values.
SourceOptions ParseSourceOptions(config::Section& section);
// The lcm_live keys of [source].
LiveSourceOptions ParseLiveSourceOptions(config::Section& section);

// Opens the input named by the options, detecting the format from its content when type = auto.
// A source that is also the robot (the simulator, live LCM) takes the stack's outputs: Source::sink().
// Throws std::runtime_error naming the path when it cannot be read or recognised.
std::unique_ptr<Source> OpenSource(const SourceOptions& options);

// The type OpenSource would pick for `path` (the first registered type whose `detect` accepts it).
// Throws std::runtime_error naming the path when there is no such file or no type recognises it.
std::string DetectFormat(const std::string& path);

}  // namespace mbot::drivers
