// The project's own event types: what every source (LCM log, live LCM, MRPT rawlog, CARMEN log,
// map file, simulator) turns its input into, what the stages emit, and what every transport
// encodes. Times are microseconds on the data's clock. Plain data only: this library links nothing
// beyond mbot_common.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "mbot/msgs/occupancy_grid.hpp"
#include "mbot/msgs/pose2d.hpp"
#include "mbot/msgs/status.hpp"

namespace mbot::msgs {

// The bound on every time the readers let in: within ±kLatestPlausibleUs (2100-01-01 in µs since the
// epoch), so the pipeline's time arithmetic (differences of two stamps) cannot overflow. A robot's
// utime (µs since the epoch, or since it booted) must also not be negative.
inline constexpr int64_t kLatestPlausibleUs = 4'102'444'800'000'000;
inline bool IsPlausibleTimeUs(int64_t t_us) { return t_us >= 0 && t_us <= kLatestPlausibleUs; }
// A stamp in seconds (CARMEN and other text logs, which may count from the log's start and so go
// slightly negative) as µs; false when it is not finite or beyond ±kLatestPlausibleUs.
inline bool StampFromSeconds(double seconds, int64_t* t_us) {
  if (!(std::abs(seconds) <= kLatestPlausibleUs * 1e-6)) return false;  // also rejects NaN
  *t_us = static_cast<int64_t>(std::llround(seconds * 1e6));
  return true;
}

struct LidarScan {
  std::vector<float> ranges_m;         // <= 0 or NaN: no return
  std::vector<float> angles_rad;       // per beam, counter-clockwise in the sensor frame (any 2π range)
  std::vector<int64_t> beam_times_us;  // per beam when the source has them, else empty
  std::vector<float> intensities;      // empty when absent
  float max_range_m = 0.0f;            // 0 when the source does not say
  // Sensor pose on the robot when the source gives one (rawlogs, CARMEN ROBOTLASER).
  Pose2D sensor_pose;
};

struct EncoderTicks {
  int64_t left_ticks = 0;  // cumulative
  int64_t right_ticks = 0;
  int32_t left_delta = 0;  // since the previous message, when the source gives it
  int32_t right_delta = 0;
  int64_t delta_time_us = 0;  // 0 when the source does not say
};

struct Imu {
  double gyro_rad_s[3] = {0, 0, 0};
  double accel_m_s2[3] = {0, 0, 0};
  double angles_rpy_rad[3] = {0, 0, 0};  // roll, pitch, yaw
  bool has_angles = false;
};

// A command to the robot's motors: a body velocity (MBOT_VEL_CMD) or duties for the two motors.
struct MotorCommand {
  enum class Kind { kVelocity, kPwm };
  Kind kind = Kind::kVelocity;
  VelocityCommand velocity;  // kVelocity
  double left_duty = 0.0;    // kPwm: duty in [-1, 1]
  double right_duty = 0.0;
  static MotorCommand Velocity(double v_m_s, double w_rad_s) { return {Kind::kVelocity, {v_m_s, w_rad_s}, 0.0, 0.0}; }
  static MotorCommand Pwm(double left, double right) { return {Kind::kPwm, {}, left, right}; }
};

// Wheel speeds the robot measured (MBOT_MOTOR_VEL, the encoders' rates) — not a command.
struct WheelSpeeds {
  double left_rad_s = 0.0;
  double right_rad_s = 0.0;
};

// A planning query from a benchmark file (botlab A* cases, Moving AI scenarios) or, live, from a
// goal sent by a GUI. Expectations are what the file says the answer must be.
struct PlanRequest {
  Pose2D start;
  Pose2D goal;
  int index = 0;                 // case number within its file (0-based)
  int expect_path = -1;          // 1: a path must exist, 0: it must not, -1: not said
  double optimal_length_m = -1;  // the optimal path length when known, else < 0
  int bucket = -1;               // Moving AI difficulty bucket, else -1
};

// One steady-state sample of a motor calibration run (the BeagleBone calibration CSV's rows): the
// duty sent to one wheel and the wheel speed its encoder measured, raw signs.
struct WheelSample {
  int channel = 0;  // the motor channel number as the file gives it (the stage maps it to a wheel)
  double duty = 0.0;
  double speed_rad_s = 0.0;
};

// A path (planned or sent by a GUI): poses in the map frame.
struct Path {
  std::vector<Pose2D> poses;
};

// The particle filter's samples (SLAM_PARTICLES): poses in the map frame and normalised weights.
struct Particles {
  std::vector<Pose2D> poses;
  std::vector<double> weights;
};

// One tag seen in a camera frame: its id and its pose in the camera frame (OpenCV's: x right, y
// down, z forward from the optical centre), in metres, as a rotation tag frame → camera frame (unit
// quaternion). On the wire (MBOT_APRILTAG_ARRAY, mbot_apriltag_array_t) it travels the way the
// botlab's publisher sends it: millimetres, roll-pitch-yaw in degrees, the quaternion as x, y, z, w.
struct TagSighting {
  TagSighting() = default;
  TagSighting(int id_, double x, double y, double z, double w, double qx_, double qy_, double qz_)
      : id(id_), x_m(x), y_m(y), z_m(z), qw(w), qx(qx_), qy(qy_), qz(qz_) {}  // a pose only
  int id = 0;
  double x_m = 0.0, y_m = 0.0, z_m = 0.0;
  double qw = 1.0, qx = 0.0, qy = 0.0, qz = 0.0;
  // Where it was in the image, when a detector here saw it (a bus that carries poses only, as
  // mbot_apriltag_array_t does, leaves `family` empty and the rest zero).
  std::string family;  // the library's name ("tagCustom48h12")
  int hamming = 0;
  double margin = 0.0;                 // decision margin
  std::array<double, 2> centre_px{};   // x, y
  std::array<double, 8> corners_px{};  // x0, y0 … x3, y3 in the library's order
  std::array<double, 9> homography{};  // tag (-1..1) → image, row-major
};

// Every tag seen in one camera frame (an empty list is a frame with none).
struct TagSightings {
  std::vector<TagSighting> tags;
};

// One 8-bit camera frame, row-major: grey (width × height bytes) or, from a source asked for colour,
// BGR (width × height × 3), shared between stages without a copy.
struct CameraFrame {
  int width = 0, height = 0;
  int channels = 1;  // 1 grey, 3 BGR
  std::shared_ptr<const std::vector<uint8_t>> pixels;
  std::string name;  // the file or device it came from, for reports
};

enum class EventKind {
  kLidar,             // LidarScan
  kOdometry,          // Pose2D, the robot's own dead-reckoning
  kEncoders,          // EncoderTicks
  kImu,               // Imu
  kMotorCommand,      // MotorCommand
  kGroundTruth,       // Pose2D, external measurement (motion capture)
  kReferencePose,     // Pose2D from another estimator (staff SLAM, corrected CARMEN poses)
  kMap,               // shared_ptr<const OccupancyGrid>
  kPlanRequest,       // PlanRequest, on the channel named after its map
  kWheelSpeed,        // WheelSpeeds measured by the robot (not a command)
  kMotorSample,       // WheelSample from a calibration file
  kCollision,         // Pose2D: the true pose at which the simulated robot touched a wall
  kPoseEstimate,      // Pose2D: the stack's own pose estimate (SLAM / localization output)
  kPath,              // Path: the planned path the controller follows
  kSlamStatus,        // SlamStatus: what SLAM's pose is worth (SLAM_STATUS)
  kMissionStatus,     // MissionStatus: the state of the robot's task (exploration, competition event)
  kParticles,         // Particles: the localization's samples
  kTagSightings,      // TagSightings: AprilTags seen in one camera frame (MBOT_APRILTAG_ARRAY)
  kCameraFrame,       // CameraFrame: an image from a camera or an image folder
  kForkliftCommand,   // ForkliftCommand: the height the forklift's tines should go to (MBOT_FORKLIFT_CMD)
  kForkliftStatus,    // ForkliftStatus: where the tines are and what they hold (MBOT_FORKLIFT_STATUS)
  kCrates,            // CrateStates: where the simulator's crates are (SIM_CRATES; the referee's truth)
  kGoal,              // Pose2D: a goal a person set (the viewer's click), map frame
  kTeleop,            // MotorCommand (velocity): a person driving (the viewer's keys); a dead man's stop
  kFrontiers,         // Frontiers: exploration's frontier regions now
  kObstacleDistance,  // shared_ptr<const DistanceGrid>: the planner's distance to obstacles
  kScore,             // ScoreStatus: the referee's score so far
  kSlamControl,       // SlamControl: a person switching SLAM's mapping or localization, or clearing the map
  kOther,             // recognised but not used by the pipeline (time sync, resets, legacy particles …)
};
// The forklift (Heavy Lift): a target height for the tines [m above the floor].
struct ForkliftCommand {
  double height_m = 0.0;
};

// What the forklift reports: the tines' height and target, and the crate on them (its tag id, -1
// when none; carrying once it is lifted off what it stood on).
struct ForkliftStatus {
  double height_m = 0.0;
  double target_m = 0.0;
  int crate_id = -1;
  bool carrying = false;
};

// The simulator's crates as they are (world frame): pose, the underside's height, and what happened
// to them — on the fork, stacked on another (its id), fallen, ever lifted clear of the floor.
struct CrateState {
  int id = 0;
  Pose2D pose;
  double z_m = 0.0;
  bool carried = false;
  int on_id = -1;
  bool fell = false;
  bool lifted = false;
};
struct CrateStates {
  std::vector<CrateState> crates;
};

// Exploration's frontiers as the explorer sees them now (map frame): known-free cells that touch
// unknown space, grouped into regions, largest first.
struct FrontierRegion {
  double x = 0.0, y = 0.0;    // the centroid [m]
  std::vector<Pose2D> cells;  // the cells' centres [m] (theta unused)
};
struct Frontiers {
  double cell_size_m = 0.05;
  std::vector<FrontierRegion> regions;
};

// The distance from each cell of a map to the nearest obstacle [m] (what the planner keeps clear
// of; unknown space counts as an obstacle when the planner says so), the map's geometry.
struct DistanceGrid {
  int width = 0, height = 0;
  double resolution_m = 0.05;
  double origin_x = 0.0, origin_y = 0.0;  // the lower-left corner of cell (0, 0) [m]
  std::vector<float> distance_m;          // row-major from the origin, width × height
};

// A person's say over SLAM (the viewer): stop or start adding scans to the map, stop or start
// correcting the pose with the scans (it then follows odometry), or clear the map (the pose and the
// map frame are kept). What is not set is left as it is.
struct SlamControl {
  std::optional<bool> mapping, localization;
  bool clear_map = false;
};

// The referee's score so far (the simulator's competition): the rubric's items and their sum.
struct ScoreItem {
  std::string name, detail;
  int points = 0, max_points = 0;
};
struct ScoreStatus {
  std::string event;  // "Maze Explorer" …
  int points = 0, max_points = 0;
  int collisions = 0;
  double elapsed_s = 0.0;  // since the event started
  std::vector<ScoreItem> items;
};

inline constexpr int kEventKindCount = static_cast<int>(EventKind::kOther) + 1;

// People's names: "motor command", "SLAM status" …
const char* ToString(EventKind kind);
// Config keys' names: "motor_command", "slam_status" … (rate limits, topic tables).
std::string KeyName(EventKind kind);
// The kind whose KeyName is `key`, or nullopt.
std::optional<EventKind> KindFromKey(const std::string& key);

using Payload = std::variant<std::monostate, LidarScan, Pose2D, EncoderTicks, Imu, MotorCommand, WheelSpeeds,
                             std::shared_ptr<const OccupancyGrid>, PlanRequest, WheelSample, Path, SlamStatus,
                             MissionStatus, Particles, TagSightings, CameraFrame, ForkliftCommand, ForkliftStatus,
                             CrateStates, Frontiers, std::shared_ptr<const DistanceGrid>, ScoreStatus, SlamControl>;

struct Event {
  int64_t t_us = 0;      // event (reception / log) time; the order of the stream
  int64_t stamp_us = 0;  // the message's own timestamp when it has one (may use another clock)
  std::string channel;
  EventKind kind = EventKind::kOther;
  Payload payload;
};

}  // namespace mbot::msgs
