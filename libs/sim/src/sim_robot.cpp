#include "mbot/sim/sim_robot.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace mbot::sim {

using msgs::EncoderTicks;
using msgs::Imu;
using msgs::LidarScan;
using msgs::MotorCommand;
using msgs::Payload;
using msgs::WheelSpeeds;
namespace {

using motion::Pose2D;

int64_t PeriodUs(double period_s, const char* what) {
  const double us = std::round(period_s * 1e6);
  if (!(us >= 1.0) || us > 1e12) {
    throw std::invalid_argument(std::string("sim robot: ") + what + " gives a period below 1 us or not finite");
  }
  return static_cast<int64_t>(us);
}

void Check(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("sim robot: " + what);
}

// One independent random stream per noise source, all derived from the run's seed, so that adding
// a draw to one sensor does not change the others.
std::mt19937_64 Stream(uint64_t seed, uint32_t stream) {
  std::seed_seq seq{static_cast<uint32_t>(seed), static_cast<uint32_t>(seed >> 32), stream};
  return std::mt19937_64(seq);
}

Event MakeEvent(int64_t t_us, const char* channel, EventKind kind, Payload payload) {
  Event e;
  e.t_us = e.stamp_us = t_us;
  e.channel = channel;
  e.kind = kind;
  e.payload = std::move(payload);
  return e;
}

}  // namespace

struct SimRobot::Impl {
  Impl(World& w, const SimRobotOptions& opt, const Pose2D& start, uint64_t seed)
      : world(w),
        o(opt),
        controller(opt.controller, opt.geometry, opt.firmware_calibration),
        odometry(opt.geometry.Odometry(), opt.firmware_odometry),
        slip_rng(Stream(seed, 1)),
        imu_rng(Stream(seed, 2)),
        lidar_rng(Stream(seed, 3)),
        camera_rng(Stream(seed, 4)),
        pose(start) {}

  void Validate() const {
    const auto& g = o.geometry;
    Check(g.wheel_radius_m > 0 && g.base_radius_m > 0 && g.gear_ratio > 0 && g.encoder_resolution > 0,
          "the geometry's radii, gear ratio and encoder resolution must be positive");
    Check(std::abs(g.left_encoder_polarity) == 1 && std::abs(g.right_encoder_polarity) == 1,
          "encoder polarities must be +1 or -1");
    Check(o.left_motor_gain > 0 && o.right_motor_gain > 0, "motor gains must be positive");
    Check(o.motor_time_constant_s >= 0, "motor_time_constant_s must be >= 0");
    Check(o.slip_stddev >= 0 && o.slip_stddev < 1, "slip_stddev must be in [0, 1)");
    Check(o.footprint_radius_m > 0, "footprint_radius_m must be positive");
    Check(o.contact_release_m >= 0, "contact_release_m must be >= 0");
    Check(o.lidar.beams >= 1, "the lidar needs at least one beam");
    Check(o.lidar.min_range_m >= 0 && o.lidar.max_range_m > o.lidar.min_range_m,
          "lidar ranges must satisfy 0 <= min_range_m < max_range_m");
    Check(o.lidar.range_noise_m >= 0, "lidar range_noise_m must be >= 0");
    Check(o.lidar.dropout >= 0 && o.lidar.dropout <= 1, "lidar dropout must be in [0, 1]");
    Check(o.imu.gyro_noise_rad_s >= 0 && o.imu.gyro_bias_initial_rad_s >= 0 && o.imu.gyro_bias_walk_rad_s_sqrt_s >= 0,
          "gyro noise and bias figures must be >= 0");
    for (double rate : {o.lidar.rate_hz, o.imu.rate_hz, o.ground_truth_rate_hz}) {
      Check(rate > 0 && std::isfinite(rate), "rates must be positive");
    }
    Check(o.physics_dt_s > 0 && o.controller.dt_s > 0 && o.slip_interval_s > 0, "periods must be positive");
  }

  void Init() {
    Validate();
    if (world.Collides(pose.x, pose.y, o.footprint_radius_m)) {
      throw std::invalid_argument("sim robot: the start pose (" + std::to_string(pose.x) + ", " +
                                  std::to_string(pose.y) + ") puts the footprint (radius " +
                                  std::to_string(o.footprint_radius_m) + " m) in a wall");
    }
    physics_us = PeriodUs(o.physics_dt_s, "physics_dt_s");
    fw_us = PeriodUs(o.controller.dt_s, "the firmware rate");
    imu_us = PeriodUs(1.0 / o.imu.rate_hz, "the IMU rate");
    gt_us = PeriodUs(1.0 / o.ground_truth_rate_hz, "the ground-truth rate");
    slip_us = PeriodUs(o.slip_interval_s, "slip_interval_s");
    lidar_us = PeriodUs(1.0 / o.lidar.rate_hz, "the lidar rate");
    next_fw = fw_us;
    next_imu = imu_us;
    next_gt = gt_us;
    next_slip = slip_us;
    next_rev_end = lidar_us;
    if (o.forklift.enabled) {
      fork = std::make_unique<Forklift>(&world, o.forklift);
      fork_us = PeriodUs(1.0 / o.forklift.status_rate_hz, "the forklift's status rate");
      next_fork = 0;  // a status, and the crates, at the start
    }
    if (o.camera.enabled) {
      camera = std::make_unique<SimCamera>(o.camera);
      camera_us = PeriodUs(1.0 / o.camera.rate_hz, "the camera rate");
      next_camera = camera_us;
    }
    rad_per_tick = o.geometry.RadPerTick();

    const int n = o.lidar.beams;
    beam_offset_us.resize(n);
    beam_angle.resize(n);
    const double step = 2.0 * M_PI / n;
    for (int k = 0; k < n; ++k) {
      beam_offset_us[k] = lidar_us * k / n;
      beam_angle[k] = static_cast<float>(o.lidar.clockwise ? -k * step : k * step);
    }
    StartRevolution(0);

    bias = o.imu.gyro_bias_initial_rad_s * normal(imu_rng);
    DrawSlip();
  }

  void DrawSlip() {
    slip_l = o.slip_stddev > 0 ? o.slip_stddev * normal(slip_rng) : 0.0;
    slip_r = o.slip_stddev > 0 ? o.slip_stddev * normal(slip_rng) : 0.0;
  }

  void StartRevolution(int64_t t_us) {
    rev_start = t_us;
    next_beam = 0;
    scan = LidarScan{};
    scan.ranges_m.reserve(beam_angle.size());
    scan.beam_times_us.reserve(beam_angle.size());
    scan.angles_rad = beam_angle;
    scan.max_range_m = static_cast<float>(o.lidar.max_range_m);
    scan.sensor_pose = o.lidar.mount;
  }

  // The count an encoder shows for a wheel rotation (forward positive) under its polarity.
  int64_t Ticks(double wheel_angle_rad, int polarity) const {
    return polarity * static_cast<int64_t>(std::floor(wheel_angle_rad / rad_per_tick));
  }

  // Wheel speed under a duty over `h` seconds: first-order lag towards the true motor's steady
  // state. Returns the rotation [rad] (exact integral of the lag), updates `w` to the end speed.
  double SpinWheel(double duty, const motion::WheelCalibration& cal, double gain, double h, double* w) const {
    const double target = gain * cal.SpeedFor(duty);
    const double tau = o.motor_time_constant_s;
    if (tau <= 0) {
      *w = target;
      return target * h;
    }
    const double a = -std::expm1(-h / tau);
    const double rotation = target * h + (*w - target) * tau * a;
    *w += (target - *w) * a;
    return rotation;
  }

  // One physics step of `h` seconds ending at `t1`.
  void Physics(double h, int64_t t1, std::vector<Event>* out) {
    double wl = w_l, wr = w_r;
    const double rot_l = SpinWheel(duty_l, o.motors.left, o.left_motor_gain, h, &wl);
    const double rot_r = SpinWheel(duty_r, o.motors.right, o.right_motor_gain, h, &wr);
    const double r = o.geometry.wheel_radius_m;
    const double dl = rot_l * r * (1.0 + slip_l), dr = rot_r * r * (1.0 + slip_r);
    const double d = 0.5 * (dl + dr), dth = (dr - dl) / (2.0 * o.geometry.base_radius_m);
    const double chord = std::abs(dth) < 1e-9 ? d : d * std::sin(0.5 * dth) / (0.5 * dth);
    Pose2D next{pose.x + chord * std::cos(pose.theta + 0.5 * dth), pose.y + chord * std::sin(pose.theta + 0.5 * dth),
                motion::WrapAngle(pose.theta + dth)};
    const bool moves = next.x != pose.x || next.y != pose.y;
    // A step that brings the footprint into a wall, or deeper, is blocked; one that touches but
    // moves away (or turns in place) is not, so a robot that touched a wall can back off. The
    // crate on the tines is under the robot's front, not in its way.
    const int ignore = fork ? fork->engaged() : -1;
    bool blocked = moves && world.Collides(next.x, next.y, o.footprint_radius_m, ignore) &&
                   world.ClearanceAt(next.x, next.y, ignore) < world.ClearanceAt(pose.x, pose.y, ignore) + 1e-9;
    bool hit = blocked;
    if (!blocked && fork) {
      const ForkContact c = fork->Check(pose, next);
      blocked = c != ForkContact::kFree;
      hit = c == ForkContact::kHit;
    }
    if (blocked) {
      // Blocked: the robot stays put and its wheels stall (the encoders stop with them).
      w_l = w_r = 0.0;
      body_rate = body_v = 0.0;
      if (hit && !contact) {
        contact = true;
        ++collisions;
        out->push_back(MakeEvent(t1, topics::kCollision, EventKind::kCollision, pose));
      }
    } else {
      w_l = wl;
      w_r = wr;
      angle_l += rot_l;
      angle_r += rot_r;
      pose = next;
      body_v = d / h;
      body_rate = dth / h;
      distance += std::abs(chord);
      if (contact && !world.Collides(pose.x, pose.y, o.footprint_radius_m + o.contact_release_m, ignore) &&
          (!fork || fork->Check(pose, pose) == ForkContact::kFree))
        contact = false;
    }
    if (fork && fork->Step(h, pose)) crates_changed = true;
  }

  msgs::CrateStates Crates() const {
    msgs::CrateStates all;
    for (const Crate& c : world.crates())
      all.crates.push_back({c.id, c.pose, c.z_m, c.carried, c.on_id, c.fell, c.lifted});
    return all;
  }

  void PublishForkliftStatus(std::vector<Event>* out) {
    msgs::ForkliftStatus st;
    st.height_m = fork->height_m();
    st.target_m = fork->target_m();
    st.crate_id = fork->engaged() >= 0 ? world.crates()[fork->engaged()].id : -1;
    st.carrying = fork->carrying();
    out->push_back(MakeEvent(now, topics::kForkliftStatus, EventKind::kForkliftStatus, st));
  }

  // Beams whose time has come by t1, each cast from the pose interpolated at its own time.
  void CastBeams(int64_t t0, const Pose2D& p0, int64_t t1, const Pose2D& p1) {
    const int n = static_cast<int>(beam_angle.size());
    const auto& l = o.lidar;
    while (next_beam < n && rev_start + beam_offset_us[next_beam] <= t1) {
      const int64_t t = rev_start + beam_offset_us[next_beam];
      const double s = t1 > t0 ? std::clamp(double(t - t0) / double(t1 - t0), 0.0, 1.0) : 1.0;
      const Pose2D sensor = motion::Interpolate(p0, p1, s).Compose(l.mount);
      double range = world.Raycast(sensor.x, sensor.y, sensor.theta + beam_angle[next_beam], l.max_range_m);
      if (range >= l.max_range_m) {
        range = 0.0;
      } else {
        if (l.range_noise_m > 0) range += l.range_noise_m * normal(lidar_rng);
        if (l.dropout > 0 && uniform(lidar_rng) < l.dropout) range = 0.0;
        if (range < l.min_range_m || range >= l.max_range_m) range = 0.0;
      }
      scan.ranges_m.push_back(static_cast<float>(range));
      scan.beam_times_us.push_back(t);
      ++next_beam;
    }
  }

  void SampleImu(std::vector<Event>* out) {
    const double dt = imu_us * 1e-6;
    bias += o.imu.gyro_bias_walk_rad_s_sqrt_s * std::sqrt(dt) * normal(imu_rng);
    const double rate = body_rate + bias + o.imu.gyro_noise_rad_s * normal(imu_rng);
    imu_yaw = motion::WrapAngle(imu_yaw + rate * dt);
    Imu imu;
    imu.gyro_rad_s[2] = rate;
    imu.accel_m_s2[0] = (body_v - imu_last_v) / dt;
    imu.accel_m_s2[1] = body_v * body_rate;
    imu.accel_m_s2[2] = 9.80665;
    imu.angles_rpy_rad[2] = imu_yaw;
    imu.has_angles = true;
    imu_last_v = body_v;
    odometry.AddImu(now, rate, imu_yaw, true);
    out->push_back(MakeEvent(now, topics::kImu, EventKind::kImu, imu));
  }

  // The Pico's control period: read the encoders, publish, update the odometry, run the wheel
  // controller; its duties drive the motors until the next period.
  void Firmware(std::vector<Event>* out) {
    const int pl = o.geometry.left_encoder_polarity, pr = o.geometry.right_encoder_polarity;
    const int64_t tl = Ticks(angle_l, pl), tr = Ticks(angle_r, pr);
    const int32_t dl = static_cast<int32_t>(tl - ticks_l), dr = static_cast<int32_t>(tr - ticks_r);
    ticks_l = tl;
    ticks_r = tr;
    // The firmware's wheel speeds, in each wheel's forward frame (what its controller works in).
    const double dt = fw_us * 1e-6;
    const double wl = pl * dl * rad_per_tick / dt, wr = pr * dr * rad_per_tick / dt;
    out->push_back(MakeEvent(now, topics::kEncoders, EventKind::kEncoders, EncoderTicks{tl, tr, dl, dr, fw_us}));
    out->push_back(MakeEvent(now, topics::kMotorVelocity, EventKind::kWheelSpeed, WheelSpeeds{wl, wr}));
    out->push_back(MakeEvent(now, topics::kOdometry, EventKind::kOdometry, odometry.AddEncoders(now, tl, tr)));
    // Like the MBot firmware, the robot stops when no velocity command came for the timeout (an
    // autonomy that died or a link that went quiet does not leave it driving).
    if (o.command_timeout_s > 0 && now - last_command_us > static_cast<int64_t>(o.command_timeout_s * 1e6)) {
      cmd_v = cmd_w = 0.0;
    }
    const motion::WheelDuties duties = controller.Update(cmd_v, cmd_w, wl, wr);
    duty_l = duties.left;
    duty_r = duties.right;
    out->push_back(MakeEvent(now, topics::kMotorPwm, EventKind::kMotorCommand, MotorCommand::Pwm(duty_l, duty_r)));
  }

  void AdvanceTo(int64_t t_end, std::vector<Event>* out) {
    while (now < t_end) {
      const int64_t grid = (now / physics_us + 1) * physics_us;
      const int64_t t1 = std::min({grid, next_fw, next_imu, next_gt, next_slip, next_rev_end, next_camera, t_end});
      const int64_t t0 = now;
      const Pose2D p0 = pose;
      Physics((t1 - t0) * 1e-6, t1, out);
      now = t1;
      CastBeams(t0, p0, t1, pose);
      if (now == next_rev_end) {
        out->push_back(MakeEvent(now, topics::kLidar, EventKind::kLidar, std::move(scan)));
        StartRevolution(now);
        next_rev_end += lidar_us;
        CastBeams(now, pose, now, pose);
      }
      if (now == next_imu) {
        SampleImu(out);
        next_imu += imu_us;
      }
      if (now == next_fw) {
        Firmware(out);
        next_fw += fw_us;
      }
      if (now == next_gt) {
        out->push_back(MakeEvent(now, topics::kTruePose, EventKind::kGroundTruth, pose));
        next_gt += gt_us;
      }
      if (now == next_slip) {
        DrawSlip();
        next_slip += slip_us;
      }
      if (now == next_camera) {
        const cv::Mat image = camera->Render(world, pose, camera_rng);
        msgs::CameraFrame frame;
        frame.width = image.cols, frame.height = image.rows;
        frame.pixels = std::make_shared<const std::vector<uint8_t>>(image.datastart, image.dataend);
        frame.name = "sim camera";
        out->push_back(MakeEvent(now, topics::kCamera, EventKind::kCameraFrame, std::move(frame)));
        next_camera += camera_us;
      }
      if (fork && (crates_changed || now >= next_fork)) {
        if (crates_changed || next_fork == 0)
          out->push_back(MakeEvent(now, topics::kCrates, EventKind::kCrates, Crates()));
        PublishForkliftStatus(out);
        if (now >= next_fork) next_fork = (now / fork_us + 1) * fork_us;
        crates_changed = false;
      }
    }
  }

  World& world;
  SimRobotOptions o;
  std::unique_ptr<Forklift> fork;     // with options.forklift.enabled
  std::unique_ptr<SimCamera> camera;  // with options.camera.enabled
  int64_t camera_us = 0, next_camera = std::numeric_limits<int64_t>::max();
  int64_t fork_us = 0, next_fork = 0;
  bool crates_changed = false;
  int fork_clamped = 0;
  motion::WheelSpeedController controller;
  motion::Gyrodometry odometry;  // the firmware's
  std::mt19937_64 slip_rng, imu_rng, lidar_rng, camera_rng;
  std::normal_distribution<double> normal{0.0, 1.0};
  std::uniform_real_distribution<double> uniform{0.0, 1.0};

  // Clock and schedules [us].
  int64_t now = 0;
  int64_t physics_us = 0, fw_us = 0, imu_us = 0, gt_us = 0, slip_us = 0, lidar_us = 0;
  int64_t next_fw = 0, next_imu = 0, next_gt = 0, next_slip = 0, next_rev_end = 0;
  double rad_per_tick = 0.0;

  // Truth.
  Pose2D pose;
  double cmd_v = 0.0, cmd_w = 0.0;
  int64_t last_command_us = 0;
  int commands_refused = 0;
  double duty_l = 0.0, duty_r = 0.0;     // what the firmware sent last
  double w_l = 0.0, w_r = 0.0;           // wheel rotational speeds [rad/s]
  double angle_l = 0.0, angle_r = 0.0;   // cumulative wheel rotation [rad]
  double slip_l = 0.0, slip_r = 0.0;     // relative ground-speed errors
  double body_v = 0.0, body_rate = 0.0;  // over the last physics step
  int collisions = 0;
  bool contact = false;
  double distance = 0.0;

  // Sensors.
  double bias = 0.0, imu_yaw = 0.0, imu_last_v = 0.0;
  int64_t ticks_l = 0, ticks_r = 0;  // at the last firmware period
  std::vector<int64_t> beam_offset_us;
  std::vector<float> beam_angle;
  int64_t rev_start = 0;
  int next_beam = 0;
  LidarScan scan;
};

SimRobot::SimRobot(World& world, const SimRobotOptions& options, const motion::Pose2D& start, uint64_t seed)
    : impl_(std::make_unique<Impl>(world, options, start, seed)) {
  impl_->Init();
}

SimRobot::~SimRobot() = default;

bool SimRobot::Command(double v_m_s, double w_rad_s) {
  const SimRobotOptions& o = impl_->o;
  impl_->last_command_us = impl_->now;
  if (!std::isfinite(v_m_s) || !std::isfinite(w_rad_s)) {  // nothing to hold to: stop
    impl_->cmd_v = impl_->cmd_w = 0.0;
    ++impl_->commands_refused;
    return false;
  }
  // Up to twice a limit the firmware clamps, as mbot_firmware does; beyond that no autonomy asked
  // for it (a corrupt exponent gives 1e30): refused, and the last good command holds.
  if (std::abs(v_m_s) > 2 * o.max_command_v_m_s || std::abs(w_rad_s) > 2 * o.max_command_w_rad_s) {
    ++impl_->commands_refused;
    return false;
  }
  impl_->cmd_v = std::clamp(v_m_s, -o.max_command_v_m_s, o.max_command_v_m_s);
  impl_->cmd_w = std::clamp(w_rad_s, -o.max_command_w_rad_s, o.max_command_w_rad_s);
  return true;
}

int SimRobot::commands_refused() const { return impl_->commands_refused; }

bool SimRobot::CommandFork(double height_m) {
  if (!impl_->fork) return false;
  if (impl_->fork->Command(height_m)) ++impl_->fork_clamped;
  return true;
}

const Forklift* SimRobot::forklift() const { return impl_->fork.get(); }
int SimRobot::forklift_commands_clamped() const { return impl_->fork_clamped; }

void SimRobot::AdvanceTo(int64_t t_us, std::vector<Event>* out) { impl_->AdvanceTo(t_us, out); }

void SimRobot::Place(const motion::Pose2D& pose) { impl_->pose = pose; }

int64_t SimRobot::now_us() const { return impl_->now; }
const motion::Pose2D& SimRobot::true_pose() const { return impl_->pose; }
int SimRobot::collisions() const { return impl_->collisions; }
bool SimRobot::in_contact() const { return impl_->contact; }
double SimRobot::distance_travelled_m() const { return impl_->distance; }
double SimRobot::left_wheel_speed_rad_s() const { return impl_->w_l; }
double SimRobot::right_wheel_speed_rad_s() const { return impl_->w_r; }
double SimRobot::left_wheel_angle_rad() const { return impl_->angle_l; }
double SimRobot::right_wheel_angle_rad() const { return impl_->angle_r; }
int64_t SimRobot::left_ticks() const { return impl_->Ticks(impl_->angle_l, impl_->o.geometry.left_encoder_polarity); }
int64_t SimRobot::right_ticks() const { return impl_->Ticks(impl_->angle_r, impl_->o.geometry.right_encoder_polarity); }
double SimRobot::gyro_bias_rad_s() const { return impl_->bias; }
const SimRobotOptions& SimRobot::options() const { return impl_->o; }

}  // namespace mbot::sim
