#include "mbot/sim/sim_source_options.hpp"

#include "mbot/msgs/topics.hpp"

#include <string>
#include <vector>

#include "mbot/common/config.hpp"
#include "mbot/common/strings.hpp"
#include "mbot/motion/motion_config.hpp"
#include "mbot/sim/sim_fidelity.hpp"
#include "mbot/vision/camera_calibration.hpp"
#include "mbot/vision/vision_config.hpp"

namespace mbot::sim {

void ParseSimRobotModel(config::Section& s, SimRobotOptions* robot) {
  const auto doc = [](const std::string& text) { return std::string("simulator: ") + text; };
  SimRobotOptions& r = *robot;
  r.physics_dt_s = s.GetDouble("physics_dt_s", r.physics_dt_s, doc("integration step of the motion [s]"), 1e-4, 0.02);
  r.footprint_radius_m =
      s.GetDouble("footprint_radius_m", r.footprint_radius_m,
                  doc("radius of the robot's disc footprint; touching a wall with it stops the robot [m]"), 0.01, 1.0);
  r.left_motor_gain = s.GetDouble(
      "left_motor_gain", r.left_motor_gain,
      doc("true left wheel speed / the speed the motor model gives its duty (per-wheel difference)"), 0.5, 1.5);
  r.right_motor_gain = s.GetDouble("right_motor_gain", r.right_motor_gain,
                                   doc("true right wheel speed / the speed the motor model gives its duty"), 0.5, 1.5);
  r.motor_time_constant_s =
      s.GetDouble("motor_time_constant_s", r.motor_time_constant_s,
                  doc("first-order lag of a wheel's speed behind its duty's steady state [s]"), 0.0, 1.0);
  r.slip_stddev =
      s.GetDouble("slip_stddev", r.slip_stddev,
                  doc("relative error of each wheel's ground speed against its rotation (std. dev.)"), 0.0, 0.5);
  r.slip_interval_s =
      s.GetDouble("slip_interval_s", r.slip_interval_s, doc("how often each wheel's slip is redrawn [s]"), 0.001, 10.0);
  const double firmware_rate_hz =
      s.GetDouble("firmware_rate_hz", 1.0 / r.controller.dt_s,
                  doc("rate of the firmware's wheel-speed controller and its encoder, wheel-speed, odometry and PWM "
                      "messages [Hz]"),
                  5.0, 1000.0);
  r.controller.dt_s = 1.0 / firmware_rate_hz;
  r.controller.v_time_constant_s =
      s.GetDouble("firmware_v_time_constant_s", r.controller.v_time_constant_s,
                  doc("the firmware's low-pass filter on the commanded forward speed [s]"), 0.0, 10.0);
  r.controller.w_time_constant_s =
      s.GetDouble("firmware_w_time_constant_s", r.controller.w_time_constant_s,
                  doc("the firmware's low-pass filter on the commanded turn rate [s]"), 0.0, 10.0);
  r.command_timeout_s = s.GetDouble("command_timeout_s", r.command_timeout_s,
                                    doc("the firmware stops the motors after this long without a velocity command "
                                        "(0: never) [s]"),
                                    0.0, 1e4);
  r.max_command_v_m_s = s.GetDouble("max_command_v_m_s", r.max_command_v_m_s,
                                    doc("the firmware clamps velocity commands to this (mbot_firmware's MAX_FWD_VEL) "
                                        "and refuses those over twice it (the last good one holds) [m/s]"),
                                    0.01, 100.0);
  r.max_command_w_rad_s = s.GetDouble("max_command_w_rad_s", r.max_command_w_rad_s,
                                      doc("... and turn rates to this (MAX_TURN_VEL) [rad/s]"), 0.01, 1000.0);
  r.ground_truth_rate_hz = s.GetDouble("ground_truth_rate_hz", r.ground_truth_rate_hz,
                                       doc("rate of the TRUE_POSE messages [Hz]"), 1.0, 1000.0);

  SimImuOptions& imu = r.imu;
  imu.rate_hz = s.GetDouble("imu_rate_hz", imu.rate_hz, doc("rate of the IMU messages [Hz]"), 1.0, 1000.0);
  imu.gyro_noise_rad_s = s.GetDouble("gyro_noise_rad_s", imu.gyro_noise_rad_s,
                                     doc("white noise of each gyro sample, standard deviation [rad/s]"), 0.0, 1.0);
  imu.gyro_bias_initial_rad_s = s.GetDouble("gyro_bias_initial_rad_s", imu.gyro_bias_initial_rad_s,
                                            doc("standard deviation of the gyro bias at start [rad/s]"), 0.0, 1.0);
  imu.gyro_bias_walk_rad_s_sqrt_s = s.GetDouble("gyro_bias_walk_rad_s_sqrt_s", imu.gyro_bias_walk_rad_s_sqrt_s,
                                                doc("random walk of the gyro bias [rad/s/sqrt(s)]"), 0.0, 1.0);

  SimLidarOptions& l = r.lidar;
  l.rate_hz = s.GetDouble("lidar_rate_hz", l.rate_hz, doc("lidar revolutions per second [Hz]"), 0.5, 100.0);
  l.beams = static_cast<int>(s.GetInt("lidar_beams", l.beams, doc("lidar beams per revolution"), 8, 100000));
  l.max_range_m = s.GetDouble("lidar_max_range_m", l.max_range_m,
                              doc("lidar range limit; farther walls give no return [m]"), 0.5, 100.0);
  l.min_range_m =
      s.GetDouble("lidar_min_range_m", l.min_range_m, doc("closer lidar returns are dropped [m]"), 0.0, 10.0);
  if (l.min_range_m >= l.max_range_m) s.Fail("lidar_min_range_m", "must be below lidar_max_range_m");
  l.range_noise_m =
      s.GetDouble("lidar_range_noise_m", l.range_noise_m, doc("lidar range noise, standard deviation [m]"), 0.0, 1.0);
  l.dropout = s.GetDouble("lidar_dropout", l.dropout, doc("probability that a lidar beam gives no return"), 0.0, 1.0);
}

SimFidelityOptions ParseSimFidelityOptions(config::Section& s) {
  SimFidelityOptions f;
  // The logged robot: its wheel constants are the log's encoders' and the simulated robot's.
  f.log_wheels = motion::ParseWheelConstants(s, &f.robot.geometry);
  ParseSimRobotModel(s, &f.robot);
  f.lidar_min_range_m = f.robot.lidar.min_range_m;
  f.lidar_max_range_m = f.robot.lidar.max_range_m;
  const config::PoseValue mount =
      s.GetPose("lidar_mount", {}, "the lidar's pose on the logged robot: x [m], y [m], theta [deg]");
  f.lidar_mount = {mount.x_m, mount.y_m, mount.theta_rad};
  f.robot.lidar.mount = f.lidar_mount;
  f.gyro_scale = s.GetDouble("gyro_scale", f.gyro_scale,
                             "multiplies the log's gyro yaw rate into rad/s (0.0174533 for deg/s)", -100.0, 100.0);
  f.max_pose_gap_s = s.GetDouble("max_pose_gap_s", f.max_pose_gap_s,
                                 "motion-capture poses further apart are not interpolated [s]", 0.001, 10.0);
  return f;
}

SimSourceOptions ParseSimSourceOptions(config::Section& s) {
  // Every key is documented as the simulator's: they exist only when the source is the simulator.
  const auto doc = [](const std::string& text) { return std::string("simulator: ") + text; };
  SimSourceOptions o;
  const std::vector<std::string> start =
      s.GetList("start", {},
                doc("where the robot starts, in the world frame: x [m], y [m], theta [deg], or 'random' "
                    "(a seeded draw from the reachable free space); default: the arena's 'start' pose, or in a "
                    "world without one (a map) the free pose with the most room"));
  o.random_start_clearance_m = s.GetDouble("random_start_clearance_m", o.random_start_clearance_m,
                                           doc("start = random keeps this far from every wall [m]"), 0.0, 10.0);
  if (start.size() == 1 && start[0] == "random") {
    o.random_start = true;
  } else if (!start.empty()) {
    if (start.size() != 3)
      s.Fail("start",
             "expected x, y, theta_deg (3 numbers) or 'random', got " + std::to_string(start.size()) + " items");
    const config::PoseValue p = s.GetPose("start", {}, "");
    o.start = motion::Pose2D{p.x_m, p.y_m, motion::WrapAngle(p.theta_rad)};
  }
  o.duration_s =
      s.GetDouble("duration_s", o.duration_s, doc("simulated time after which the run ends [s]"), 0.001, 1e6);
  o.realtime_factor = s.GetDouble("realtime_factor", o.realtime_factor,
                                  doc("0: as fast as possible; else simulated time runs this many times the wall clock "
                                      "(1 for the simulated robot on the LCM bus)"),
                                  0.0, 1000.0);
  if (o.realtime_factor > 0 && o.realtime_factor < 0.01) s.Fail("realtime_factor", "must be 0 (off) or at least 0.01");

  SimRobotOptions& r = o.robot;
  ParseSimRobotModel(s, &r);
  ForkliftOptions& f = r.forklift;
  f.enabled = s.GetBool("forklift", f.enabled,
                        doc("the robot has a forklift (Heavy Lift): tines at its front that lift crates, commanded "
                            "on MBOT_FORKLIFT_CMD"));
  f.tip_x_m = s.GetDouble("fork_tip_x_m", f.tip_x_m, doc("forklift: the tines' tips ahead of the robot's centre [m]"),
                          0.01, 1.0);
  f.tine_length_m = s.GetDouble("fork_tine_length_m", f.tine_length_m,
                                doc("forklift: how far a crate slides onto the tines [m]"), 0.005, 1.0);
  f.min_height_m = s.GetDouble("fork_min_height_m", f.min_height_m, doc("forklift: lowest tine height [m]"), 0.0, 1.0);
  f.max_height_m = s.GetDouble("fork_max_height_m", f.max_height_m, doc("forklift: highest tine height [m]"), 0.0, 1.0);
  f.speed_m_s = s.GetDouble("fork_speed_m_s", f.speed_m_s, doc("forklift: how fast the tines move [m/s]"), 0.001, 1.0);
  f.slot_m = s.GetDouble("fork_slot_m", f.slot_m,
                         doc("forklift: height of the slot in a crate's base that the tines enter [m]"), 0.001, 0.5);
  f.engage_depth_m = s.GetDouble("fork_engage_depth_m", f.engage_depth_m,
                                 doc("forklift: the tips this far inside a crate's face engage it [m]"), 0.001, 1.0);
  f.engage_lateral_m =
      s.GetDouble("fork_engage_lateral_m", f.engage_lateral_m,
                  doc("forklift: the robot's centre line within this of the crate's centre to enter it [m]"), 0.0, 0.5);
  f.engage_heading_deg =
      s.GetDouble("fork_engage_heading_deg", f.engage_heading_deg,
                  doc("forklift: the robot square to the crate's face within this to enter it [deg]"), 0.0, 44.0);
  f.stack_tolerance_m =
      s.GetDouble("fork_stack_tolerance_m", f.stack_tolerance_m,
                  doc("forklift: a crate set down with its centre within this of the one below is stacked; farther "
                      "off, it falls [m]"),
                  0.0, 0.5);
  f.status_rate_hz = s.GetDouble("fork_status_rate_hz", f.status_rate_hz,
                                 doc("forklift: rate of MBOT_FORKLIFT_STATUS [Hz]"), 0.1, 1000.0);
  if (f.max_height_m <= f.min_height_m) s.Fail("fork_max_height_m", "must be above fork_min_height_m");
  if (f.tine_length_m > f.tip_x_m) s.Fail("fork_tine_length_m", "must not exceed fork_tip_x_m");
  if (f.engage_depth_m >= f.tine_length_m) s.Fail("fork_engage_depth_m", "must be below fork_tine_length_m");

  SimCameraOptions& c = r.camera;
  c.enabled =
      s.GetBool("camera", c.enabled,
                doc(std::string("the robot has a camera: grey frames of the floor, walls and crates (with their "
                                "tags) on ") +
                    msgs::topics::kCamera));
  const std::string calibration = s.GetPath(
      "camera_calibration", "",
      doc("the camera's intrinsics and image size: a camera.yaml (OpenCV's keys); empty: 640 x 480, fx = fy = 530, "
          "centred, no distortion"));
  if (!calibration.empty() && !s.describing()) {
    try {
      const vision::CalibrationResult cal = vision::ReadCameraYaml(calibration);
      if (cal.image_width < 16 || cal.image_height < 16 || cal.image_width > 8192 || cal.image_height > 8192) {
        throw std::invalid_argument(calibration + ": image_width x image_height = " + std::to_string(cal.image_width) +
                                    " x " + std::to_string(cal.image_height) +
                                    " is outside the simulated camera's 16-8192 px a side");
      }
      c.width = cal.image_width, c.height = cal.image_height;
      c.intrinsics = vision::IntrinsicsFromYaml(calibration);
    } catch (const std::exception& e) {
      s.Fail("camera_calibration", e.what());
    }
  }
  c.mount = vision::ParseCameraMount(s, c.mount);
  c.rate_hz = s.GetDouble("camera_rate_hz", c.rate_hz, doc("camera frames per second [Hz]"), 0.1, 200.0);
  c.tag_size_m = s.GetDouble("camera_tag_size_m", c.tag_size_m,
                             doc("the tags printed on the crates: the black square's side [m]"), 0.005, 1.0);
  c.wall_height_m =
      s.GetDouble("wall_height_m", c.wall_height_m, doc("height of the walls the camera sees [m]"), 0.01, 10.0);
  c.noise_stddev =
      s.GetDouble("camera_noise", c.noise_stddev,
                  doc("camera: Gaussian noise of each pixel, standard deviation [grey levels]"), 0.0, 100.0);
  c.blur_sigma_px =
      s.GetDouble("camera_blur_px", c.blur_sigma_px, doc("camera: Gaussian blur, sigma [pixels] (0: none)"), 0.0, 20.0);
  c.exposure_change = s.GetDouble(
      "camera_exposure_change", c.exposure_change,
      doc("camera: each frame's gain is drawn uniformly from [1 - this, 1 + this] (exposure changes)"), 0.0, 0.9);
  return o;
}

}  // namespace mbot::sim
