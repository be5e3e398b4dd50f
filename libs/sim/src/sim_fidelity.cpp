#include "mbot/sim/sim_fidelity.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <queue>
#include <random>
#include <stdexcept>
#include <string>
#include <variant>

namespace mbot::sim {

using motion::Pose2D;
using motion::TimedPose;
using msgs::EventKind;

namespace {

constexpr double kMinPathM = 0.5;           // drift per metre needs a path to divide by
constexpr double kMinTurnRad = 0.5 * M_PI;  // drift per turn needs turning to divide by
constexpr int64_t kWindowUs = 200'000;      // encoder and gyro rates are compared over this
constexpr int64_t kReorderUs = 2'000'000;   // stamps this near their event time share its clock

double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(q * (v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

double Rms(double sum_sq, long long n) { return n > 0 ? std::sqrt(sum_sq / n) : NAN; }

}  // namespace

struct SimFidelity::Impl {
  Impl(const SimFidelityOptions& o, std::optional<World> a, uint64_t s)
      : options(o),
        arena(std::move(a)),
        seed(s),
        empty(World::ParseArena("name open floor\nresolution 0.1\nbox -50 -50 50 50\n", "sim_fidelity")) {}

  SimFidelityOptions options;
  std::optional<World> arena;
  uint64_t seed;
  World empty;
  std::unique_ptr<SimRobot> robot;
  int64_t t0 = -1;  // the first truth time: the simulation's zero
  std::vector<TimedPose> truth, odometry, sim;
  std::vector<msgs::Event> scratch;
  SimFidelityResult r;
  // Encoders and gyro are compared over windows of at least kWindowUs (rates between single
  // messages would carry the stamps' jitter).
  struct Window {
    bool open = false;
    int64_t t = 0;
  };
  Window enc, imu;
  int64_t enc_l = 0, enc_r = 0;
  double sim_l = 0, sim_r = 0;  // the simulated wheels' rotations at the window's start [rad]
  int64_t log_t0 = -1;          // the log's first truth time (begin_s and end_s count from it)
  int64_t last_truth_us = -1;
  bool comparing = false;  // past begin_s
  double wheel_sq = 0, wheel_sum = 0;
  long long wheel_n = 0;
  double gyro_sum = 0, yaw_sq = 0, yaw_sum = 0;
  int gyro_count = 0;
  long long yaw_n = 0;
  // Scans waiting for the truth to pass their last beam.
  std::deque<std::pair<int64_t, msgs::LidarScan>> scans;
  std::vector<double> residuals, spreads;
  std::mt19937_64 rng{seed ^ 0x51d5f1de11ULL};
  std::uniform_real_distribution<double> unit{0.0, 1.0};
  std::normal_distribution<double> noise{0.0, 1.0};
  long long real_none = 0, sim_none = 0;

  void Advance(int64_t t_us) {
    if (!robot || t_us <= t0) return;
    robot->AdvanceTo(t_us - t0, &scratch);
    if (!comparing) return scratch.clear();
    for (const msgs::Event& e : scratch) {
      if (e.kind == EventKind::kImu) sim_gyro_sum += std::get<msgs::Imu>(e.payload).gyro_rad_s[2], ++sim_gyro_count;
    }
    scratch.clear();
    if (sim.empty() || sim.back().t_us < t_us) sim.push_back({t_us, robot->true_pose()});
  }

  void Encoders(int64_t t, const msgs::EncoderTicks& e) {
    const double radius = options.robot.geometry.wheel_radius_m;
    const double sl = robot->left_wheel_angle_rad(), sr = robot->right_wheel_angle_rad();
    if (enc.open && t - enc.t < kWindowUs) return;
    if (enc.open) {
      const double dt = (t - enc.t) * 1e-6;
      const double real_l = (e.left_ticks - enc_l) * options.log_wheels.left_m_per_tick / dt;
      const double real_r = (e.right_ticks - enc_r) * options.log_wheels.right_m_per_tick / dt;
      const double sim_lv = (sl - sim_l) * radius / dt;
      const double sim_rv = (sr - sim_r) * radius / dt;
      for (const double d : {sim_lv - real_l, sim_rv - real_r}) wheel_sq += d * d, wheel_sum += d, ++wheel_n;
      r.wheel_windows.push_back({(t - log_t0) * 1e-6, real_l, real_r, sim_lv, sim_rv});
      ++r.encoder_samples;
    }
    enc = {true, t};
    enc_l = e.left_ticks, enc_r = e.right_ticks, sim_l = sl, sim_r = sr;
  }

  // The simulated gyro (its noise and bias, as the simulated robot publishes it) against the log's,
  // each averaged over the same window.
  void Gyro(int64_t t, const msgs::Imu& m) {
    if (!imu.open) {
      imu = {true, t};
      sim_gyro_sum = 0, sim_gyro_count = 0;
      return;
    }
    gyro_sum += m.gyro_rad_s[2] * options.gyro_scale, ++gyro_count;
    if (t - imu.t < kWindowUs || sim_gyro_count == 0) return;
    const double sim_rate = sim_gyro_sum / sim_gyro_count, real_rate = gyro_sum / gyro_count;
    const double d = sim_rate - real_rate;
    yaw_sq += d * d, yaw_sum += d, ++yaw_n;
    r.yaw_windows.push_back({(t - log_t0) * 1e-6, real_rate, sim_rate});
    ++r.gyro_samples;
    imu = {true, t};
    gyro_sum = 0, gyro_count = 0, sim_gyro_sum = 0, sim_gyro_count = 0;
  }
  double sim_gyro_sum = 0;
  int sim_gyro_count = 0;

  // The beams' times on the log's clock: the scan's event time less how far each beam's own stamp
  // lies before the scan's stamp (the two clocks may differ; their differences do not).
  void CompareScan(int64_t t, int64_t stamp, const msgs::LidarScan& s) {
    const int64_t gap = static_cast<int64_t>(options.max_pose_gap_s * 1e6);
    const bool timed = s.beam_times_us.size() == s.ranges_m.size() && !s.beam_times_us.empty();
    if (timed) {
      const auto [lo, hi] = std::minmax_element(s.beam_times_us.begin(), s.beam_times_us.end());
      spreads.push_back((*hi - *lo) * 1e-6);
    }
    ++r.scans;
    for (size_t i = 0; i < s.ranges_m.size() && i < s.angles_rad.size(); ++i) {
      const int64_t ti = timed ? t - (stamp - s.beam_times_us[i]) : t;
      Pose2D pose;
      if (!motion::InterpolateAt(truth, ti, gap, &pose)) continue;
      const Pose2D sensor = pose.Compose(options.lidar_mount);
      // The simulated lidar's range: the ray cast with its noise and dropout (SimLidarOptions).
      double sim_range = arena->Raycast(sensor.x, sensor.y, sensor.theta + s.angles_rad[i], options.lidar_max_range_m);
      if (sim_range < options.lidar_max_range_m) {
        if (unit(rng) < options.robot.lidar.dropout)
          sim_range = options.lidar_max_range_m;
        else
          sim_range += noise(rng) * options.robot.lidar.range_noise_m;
      }
      const double real = s.ranges_m[i];
      const bool real_return =
          std::isfinite(real) && real >= options.lidar_min_range_m && real < options.lidar_max_range_m;
      const bool sim_return = sim_range >= options.lidar_min_range_m && sim_range < options.lidar_max_range_m;
      ++r.beams;
      real_none += !real_return;
      sim_none += !sim_return;
      if (real_return && sim_return) residuals.push_back(real - sim_range);
    }
  }

  // A scan's beams were all measured by its event time: it is compared once the truth passed that
  // (or at the end).
  void FlushScans(bool all) {
    while (!scans.empty() && (all || (!truth.empty() && truth.back().t_us >= scans.front().first))) {
      CompareScan(scans.front().first, scan_stamps.front(), scans.front().second);
      scans.pop_front();
      scan_stamps.pop_front();
    }
  }
  std::deque<int64_t> scan_stamps;

  // The reorder window: events by their placed time (then by arrival).
  struct Placed {
    int64_t t_us;
    long long order;
    msgs::Event event;
    bool operator>(const Placed& o) const { return t_us != o.t_us ? t_us > o.t_us : order > o.order; }
  };
  std::priority_queue<Placed, std::vector<Placed>, std::greater<Placed>> pending;
  long long order = 0;
  void Process(const msgs::Event& ev, int64_t t);
};

SimFidelity::SimFidelity(const SimFidelityOptions& options, std::optional<World> arena, uint64_t seed)
    : impl_(std::make_unique<Impl>(options, std::move(arena), seed)) {}

SimFidelity::~SimFidelity() = default;

void SimFidelity::Impl::Process(const msgs::Event& ev, int64_t t) {
  Impl& m = *this;
  if (ev.kind == EventKind::kGroundTruth && m.log_t0 < 0) m.log_t0 = t;
  if (m.log_t0 < 0) return;  // before motion capture: nothing to compare with
  const double since_s = (t - m.log_t0) * 1e-6;
  if (since_s > m.options.end_s) return;
  if (ev.kind == EventKind::kGroundTruth) {
    const Pose2D& p = std::get<Pose2D>(ev.payload);
    if (t < m.last_truth_us) return;
    m.last_truth_us = t;
    if (!m.robot) {
      // The simulated robot starts where motion capture first saw the real one, at rest.
      m.robot = std::make_unique<SimRobot>(m.empty, m.options.robot, p, m.seed);
      m.t0 = t;
    }
    m.Advance(t);
    if (!m.comparing && since_s >= m.options.begin_s) {
      // The compared part begins: the simulated robot (still moving as it was) is re-placed where the
      // real one is.
      m.comparing = true;
      if (m.options.begin_s > 0) m.robot->Place(p);
      m.sim.push_back({t, p});
    }
    if (!m.comparing) return;
    m.truth.push_back({t, p});
    if (m.arena) m.FlushScans(false);
    return;
  }
  if (!m.robot) return;  // before motion capture: nothing to compare with
  m.Advance(t);
  if (!m.comparing && ev.kind != EventKind::kMotorCommand) return;
  switch (ev.kind) {
    case EventKind::kMotorCommand: {
      const auto& c = std::get<msgs::MotorCommand>(ev.payload);
      if (c.kind != msgs::MotorCommand::Kind::kVelocity) return;
      m.r.commands += m.comparing;
      m.r.commands_refused += !m.robot->Command(c.velocity.v_m_s, c.velocity.w_rad_s);
      return;
    }
    case EventKind::kEncoders: m.Encoders(t, std::get<msgs::EncoderTicks>(ev.payload)); return;
    case EventKind::kImu: m.Gyro(t, std::get<msgs::Imu>(ev.payload)); return;
    case EventKind::kOdometry: {
      const Pose2D& p = std::get<Pose2D>(ev.payload);
      if (m.odometry.empty() || t >= m.odometry.back().t_us) m.odometry.push_back({t, p});
      return;
    }
    case EventKind::kLidar:
      if (!m.arena) return;
      m.scans.emplace_back(t, std::get<msgs::LidarScan>(ev.payload));
      m.scan_stamps.push_back(ev.stamp_us);
      m.FlushScans(false);
      return;
    default: return;
  }
}

// Each message is placed at its own stamp when the stamp shares the log's clock (within 2 s of the
// event time: the robot's streams of a legacy log arrived in bursts up to 1.6 s late, while the
// motion capture was stamped on arrival), else at its event time, and the events are taken in that
// order through a reorder window of the same 2 s.
void SimFidelity::Add(const msgs::Event& ev) {
  Impl& m = *impl_;
  const bool stamped = ev.stamp_us > 0 && std::llabs(ev.stamp_us - ev.t_us) < kReorderUs;
  m.pending.push({stamped ? ev.stamp_us : ev.t_us, m.order++, ev});
  while (!m.pending.empty() && m.pending.top().t_us < ev.t_us - kReorderUs) {
    m.Process(m.pending.top().event, m.pending.top().t_us);
    m.pending.pop();
  }
}

SimFidelityResult SimFidelity::Finish() {
  Impl& m = *impl_;
  for (; !m.pending.empty(); m.pending.pop()) m.Process(m.pending.top().event, m.pending.top().t_us);
  if (m.truth.size() < 2) throw std::runtime_error("sim_fidelity: the log has no motion capture (TRUE_POSE)");
  if (m.r.commands == 0)
    throw std::runtime_error("sim_fidelity: the log has no velocity commands after its first motion-capture pose");
  if (m.arena) m.FlushScans(true);
  SimFidelityResult& r = m.r;
  const int64_t gap = static_cast<int64_t>(m.options.max_pose_gap_s * 1e6);
  r.duration_s = (m.truth.back().t_us - m.truth.front().t_us) * 1e-6;
  double turn = 0;
  // The path and the turning, counted in steps of at least 1 cm and 0.5° so the motion capture's
  // jitter (sub-millimetre, every 10 ms) does not add up while the robot stands.
  Pose2D at = m.truth.front().pose;
  double heading = at.theta;
  for (const TimedPose& p : m.truth) {
    const double step = std::hypot(p.pose.x - at.x, p.pose.y - at.y);
    if (step >= 0.01) r.true_path_m += step, at = p.pose;
    const double dtheta = std::abs(motion::WrapAngle(p.pose.theta - heading));
    if (dtheta >= 0.5 * M_PI / 180) turn += dtheta, heading = p.pose.theta;
  }
  r.true_turn_deg = turn * 180 / M_PI;
  // The log's odometry in the truth frame: anchored where the first truth pose meets it.
  Pose2D anchor;
  bool anchored = false;
  if (!m.odometry.empty()) {
    Pose2D o0;
    if (motion::InterpolateAt(m.odometry, m.truth.front().t_us, gap, &o0) || (o0 = m.odometry.front().pose, true)) {
      anchor = m.truth.front().pose.Compose(o0.Inverse());
      anchored = true;
    }
  }
  // Errors along the run at the simulated samples (each paired with the truth at its time), then at
  // the end: the last simulated sample (the simulation runs to the log's last event).
  double sim_sq = 0, odo_sq = 0;
  long long sim_n = 0, odo_n = 0;
  for (const TimedPose& s : m.sim) {
    Pose2D t;
    if (!motion::InterpolateAt(m.truth, s.t_us, gap, &t)) continue;
    sim_sq += (s.pose.x - t.x) * (s.pose.x - t.x) + (s.pose.y - t.y) * (s.pose.y - t.y), ++sim_n;
    r.path_t_s.push_back((s.t_us - m.t0) * 1e-6);
    r.truth_path.push_back(t);
    r.sim_path.push_back(s.pose);
    Pose2D o;
    if (anchored && motion::InterpolateAt(m.odometry, s.t_us, gap, &o)) {
      const Pose2D a = anchor.Compose(o);
      odo_sq += (a.x - t.x) * (a.x - t.x) + (a.y - t.y) * (a.y - t.y), ++odo_n;
      r.odometry_path.push_back(a);
    } else {
      r.odometry_path.push_back({NAN, NAN, NAN});
    }
  }
  r.path_rmse_m = Rms(sim_sq, sim_n);
  r.odometry_rmse_m = Rms(odo_sq, odo_n);
  const Pose2D truth_end = m.truth.back().pose;
  const int64_t t_end = m.truth.back().t_us;
  Pose2D sim_end;
  if (!motion::InterpolateAt(m.sim, t_end, gap, &sim_end)) sim_end = m.sim.back().pose;
  const double per_m = r.true_path_m >= kMinPathM ? 1.0 / r.true_path_m : NAN;
  const double per_turn = turn >= kMinTurnRad ? 2 * M_PI / turn : NAN;
  r.path_final_error_m = std::hypot(sim_end.x - truth_end.x, sim_end.y - truth_end.y);
  r.path_drift_m_per_m = r.path_final_error_m * per_m;
  r.heading_drift_deg_per_turn = std::abs(motion::WrapAngle(sim_end.theta - truth_end.theta)) * 180 / M_PI * per_turn;
  r.odometry_final_error_m = NAN, r.odometry_drift_m_per_m = NAN, r.odometry_heading_drift_deg_per_turn = NAN;
  Pose2D o_end;
  if (anchored && motion::InterpolateAt(m.odometry, t_end, gap, &o_end)) {
    const Pose2D a = anchor.Compose(o_end);
    r.odometry_final_error_m = std::hypot(a.x - truth_end.x, a.y - truth_end.y);
    r.odometry_drift_m_per_m = r.odometry_final_error_m * per_m;
    r.odometry_heading_drift_deg_per_turn =
        std::abs(motion::WrapAngle(a.theta - truth_end.theta)) * 180 / M_PI * per_turn;
  }
  r.wheel_speed_rmse_m_s = Rms(m.wheel_sq, m.wheel_n);
  r.wheel_speed_bias_m_s = m.wheel_n > 0 ? m.wheel_sum / m.wheel_n : NAN;
  r.yaw_rate_rmse_rad_s = Rms(m.yaw_sq, m.yaw_n);
  r.yaw_rate_bias_rad_s = m.yaw_n > 0 ? m.yaw_sum / m.yaw_n : NAN;
  // Lidar.
  std::vector<double> abs_res;
  abs_res.reserve(m.residuals.size());
  for (double d : m.residuals) abs_res.push_back(std::abs(d));
  r.beams_compared = static_cast<long long>(m.residuals.size());
  r.scan_range_residual_median_m = Quantile(abs_res, 0.5);
  r.scan_range_residual_p95_m = Quantile(abs_res, 0.95);
  r.scan_range_residual_signed_median_m = Quantile(m.residuals, 0.5);
  r.no_return_rate_real = r.beams > 0 ? double(m.real_none) / r.beams : NAN;
  r.no_return_rate_sim = r.beams > 0 ? double(m.sim_none) / r.beams : NAN;
  r.beam_time_spread_real_s = Quantile(m.spreads, 0.5);
  const double bin = m.options.residual_histogram_bin_m, range = m.options.residual_histogram_range_m;
  const int bins = std::max(1, static_cast<int>(std::lround(2 * range / bin)));
  r.residual_histogram.assign(static_cast<size_t>(bins), 0);
  for (double d : m.residuals) {
    const int k = static_cast<int>(std::floor((d + range) / bin));
    if (k >= 0 && k < bins) ++r.residual_histogram[static_cast<size_t>(k)];
  }
  r.commands_refused = m.robot->commands_refused();
  return r;
}

}  // namespace mbot::sim
