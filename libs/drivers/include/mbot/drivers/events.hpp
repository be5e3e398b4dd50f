// The project's own event types: what every source (LCM log, live LCM, MRPT rawlog, CARMEN log,
// map file, simulator) turns its input into. Times are microseconds on the data's clock.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "mbot/mapping/occupancy_grid.hpp"
#include "mbot/mapping/slam.hpp"
#include "mbot/mission/mission_state.hpp"
#include "mbot/motion/motion_controller.hpp"
#include "mbot/motion/pose2d.hpp"

namespace mbot::drivers {

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
  motion::Pose2D sensor_pose;
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
  motion::VelocityCommand velocity;  // kVelocity
  double left_duty = 0.0;            // kPwm: duty in [-1, 1]
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
  motion::Pose2D start;
  motion::Pose2D goal;
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
  std::vector<motion::Pose2D> poses;
};

// The particle filter's samples (SLAM_PARTICLES): poses in the map frame and normalised weights.
struct Particles {
  std::vector<motion::Pose2D> poses;
  std::vector<double> weights;
};

// One tag seen in a camera frame: its id and its pose in the camera frame (OpenCV's: x right, y
// down, z forward from the optical centre), in metres, as a rotation tag frame → camera frame (unit
// quaternion). On the wire (MBOT_APRILTAG_ARRAY, mbot_apriltag_array_t) it travels the way the
// botlab's publisher sends it: millimetres, roll-pitch-yaw in degrees, the quaternion as x, y, z, w.
struct TagSighting {
  int id = 0;
  double x_m = 0.0, y_m = 0.0, z_m = 0.0;
  double qw = 1.0, qx = 0.0, qy = 0.0, qz = 0.0;
};

// Every tag seen in one camera frame (an empty list is a frame with none).
struct TagSightings {
  std::vector<TagSighting> tags;
};

// One 8-bit grey camera frame (row-major, width × height bytes), shared between stages without a copy.
struct CameraFrame {
  int width = 0, height = 0;
  std::shared_ptr<const std::vector<uint8_t>> pixels;
  std::string name;  // the file or device it came from, for reports
};

enum class EventKind {
  kLidar,            // LidarScan
  kOdometry,         // Pose2D, the robot's own dead-reckoning
  kEncoders,         // EncoderTicks
  kImu,              // Imu
  kMotorCommand,     // MotorCommand
  kGroundTruth,      // Pose2D, external measurement (motion capture)
  kReferencePose,    // Pose2D from another estimator (staff SLAM, corrected CARMEN poses)
  kMap,              // shared_ptr<const OccupancyGrid>
  kPlanRequest,      // PlanRequest, on the channel named after its map
  kWheelSpeed,       // WheelSpeeds measured by the robot (not a command)
  kMotorSample,      // WheelSample from a calibration file
  kCollision,        // Pose2D: the true pose at which the simulated robot touched a wall
  kPoseEstimate,     // Pose2D: the stack's own pose estimate (SLAM / localization output)
  kPath,             // Path: the planned path the controller follows
  kSlamStatus,       // mapping::SlamStatus: what SLAM's pose is worth (SLAM_STATUS)
  kMissionStatus,    // mission::MissionStatus: the state of the robot's task (exploration, competition event)
  kParticles,        // Particles: the localization's samples
  kTagSightings,     // TagSightings: AprilTags seen in one camera frame (MBOT_APRILTAG_ARRAY)
  kCameraFrame,      // CameraFrame: an image from a camera or an image folder
  kForkliftCommand,  // ForkliftCommand: the height the forklift's tines should go to (MBOT_FORKLIFT_CMD)
  kForkliftStatus,   // ForkliftStatus: where the tines are and what they hold (MBOT_FORKLIFT_STATUS)
  kCrates,           // CrateStates: where the simulator's crates are (SIM_CRATES; the referee's truth)
  kOther,            // recognised but not used by the pipeline (time sync, resets, legacy particles …)
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
  motion::Pose2D pose;
  double z_m = 0.0;
  bool carried = false;
  int on_id = -1;
  bool fell = false;
  bool lifted = false;
};
struct CrateStates {
  std::vector<CrateState> crates;
};

const char* ToString(EventKind kind);

using Payload = std::variant<std::monostate, LidarScan, motion::Pose2D, EncoderTicks, Imu, MotorCommand, WheelSpeeds,
                             std::shared_ptr<const mapping::OccupancyGrid>, PlanRequest, WheelSample, Path,
                             mapping::SlamStatus, mission::MissionStatus, Particles, TagSightings, CameraFrame,
                             ForkliftCommand, ForkliftStatus, CrateStates>;

struct Event {
  int64_t t_us = 0;      // event (reception / log) time; the order of the stream
  int64_t stamp_us = 0;  // the message's own timestamp when it has one (may use another clock)
  std::string channel;
  EventKind kind = EventKind::kOther;
  Payload payload;
};

}  // namespace mbot::drivers
