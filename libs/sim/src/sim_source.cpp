#include "mbot/sim/sim_source.hpp"

#include <algorithm>
#include <chrono>
#include <thread>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "mbot/common/log.hpp"
#include "mbot/common/strings.hpp"

namespace mbot::sim {
namespace {

using msgs::ChannelInfo;
using msgs::MotorCommand;
using msgs::SourceOptions;

motion::Pose2D StartPose(const SourceOptions& options, const SimSourceOptions& sim, const World& world) {
  if (sim.start) return *sim.start;
  if (sim.random_start) {
    try {
      return RandomFreePose(world, sim.random_start_clearance_m, options.seed);
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(options.path + ": start = random: " + e.what());
    }
  }
  const std::vector<motion::Pose2D> starts = world.PosesLabelled("start");
  if (!starts.empty()) return starts.front();
  // A map has no start pose: the free pose with the most room (set [source] start to choose one).
  try {
    const motion::Pose2D p = MostRoomPose(world, options.seed);
    mbot::log::Info("sim: " + options.path + " has no start pose; starting at the free pose with the most room (" +
                    std::to_string(p.x) + ", " + std::to_string(p.y) + ", " + std::to_string(p.theta * 180 / M_PI) +
                    " deg)");
    return p;
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(options.path + ": " + e.what() + "; set [source] start = x, y, theta_deg");
  }
}

std::unique_ptr<SimRobot> MakeRobot(const SourceOptions& options, const SimSourceOptions& sim, World& world,
                                    const motion::Pose2D& start) {
  try {
    return std::make_unique<SimRobot>(world, sim.robot, start, options.seed);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(options.path + ": " + e.what());
  }
}

}  // namespace

SimSource::SimSource(const SourceOptions& options, const SimSourceOptions& sim)
    : path_(options.path),
      seed_(options.seed),
      duration_us_(static_cast<int64_t>(std::llround(sim.duration_s * 1e6))),
      world_(World::Load(options.path)),
      start_(StartPose(options, sim, world_)),
      robot_(MakeRobot(options, sim, world_, start_)),
      realtime_factor_(sim.realtime_factor) {
  if (const auto& area = world_.crate_area()) {
    // The robot reads the world by reference: crates added now are seen from its first step.
    try {
      PlaceCratesAtRandom(&world_, *area, seed_, start_, sim.robot.footprint_radius_m + 0.1);
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(options.path + ": " + e.what());
    }
  }
  const std::string gen = "simulated";
  channels_[topics::kEncoders] = ChannelInfo{"mbot_encoders_t", gen, EventKind::kEncoders, true};
  channels_[topics::kImu] = ChannelInfo{"mbot_imu_t", gen, EventKind::kImu, true};
  channels_[topics::kOdometry] = ChannelInfo{"pose2D_t", gen, EventKind::kOdometry, true};
  channels_[topics::kMotorPwm] = ChannelInfo{"mbot_motor_pwm_t", gen, EventKind::kMotorCommand, true};
  channels_[topics::kMotorVelocity] = ChannelInfo{"mbot_motor_vel_t", gen, EventKind::kWheelSpeed, true};
  channels_[topics::kLidar] = ChannelInfo{"lidar_t", gen, EventKind::kLidar, true};
  channels_[topics::kTruePose] = ChannelInfo{"pose2D_t", gen, EventKind::kGroundTruth, true};
  channels_[topics::kCollision] = ChannelInfo{"pose2D_t", gen, EventKind::kCollision, true};
  if (sim.robot.forklift.enabled) {
    channels_[topics::kForkliftStatus] = ChannelInfo{"mbot_forklift_status_t", gen, EventKind::kForkliftStatus, true};
    channels_[topics::kCrates] = ChannelInfo{"crate states", gen, EventKind::kCrates, true};
  }
  if (sim.robot.camera.enabled)
    channels_[topics::kCamera] = ChannelInfo{"8-bit grey image", gen, EventKind::kCameraFrame, true};
}

std::optional<Event> SimSource::Next() {
  while (next_ == buffer_.size()) {
    buffer_.clear();
    next_ = 0;
    const int64_t now = robot_->now_us();
    if (ended_ || now >= duration_us_) return std::nullopt;
    const int64_t step = std::max<int64_t>(1, std::llround(robot_->options().physics_dt_s * 1e6));
    if (realtime_factor_ > 0) {  // keep simulated time with the wall clock, from the first event asked for
      if (!paced_)
        paced_ = true, wall0_ = std::chrono::steady_clock::now() -
                                std::chrono::microseconds(static_cast<int64_t>(now / realtime_factor_));
      std::this_thread::sleep_until(wall0_ + std::chrono::microseconds(static_cast<int64_t>(now / realtime_factor_)));
    }
    robot_->AdvanceTo(std::min(now + step, duration_us_), &buffer_);
  }
  if (ended_) return std::nullopt;
  return std::move(buffer_[next_++]);
}

double SimSource::Progress() const {
  if (ended_ || duration_us_ <= 0) return 1.0;
  return std::min(1.0, double(robot_->now_us()) / double(duration_us_));
}

std::vector<std::pair<std::string, std::string>> SimSource::Details() const {
  std::ostringstream start, duration;
  start << start_.x << ", " << start_.y << ", " << start_.theta * 180.0 / M_PI << " deg";
  duration << duration_us_ * 1e-6 << " s";
  std::vector<std::pair<std::string, std::string>> d = {
      {"world", world_.name().empty() ? path_ : world_.name()},
      {"world file", path_},
      {"start", start.str()},
      {"seed", std::to_string(seed_)},
      {"duration", duration.str()},
      {"collisions", std::to_string(robot_->collisions())},
      {"velocity commands refused", std::to_string(robot_->commands_refused())}};
  if (robot_->forklift()) {
    d.push_back({"crates", std::to_string(world_.crates().size())});
    d.push_back({"forklift commands clamped", std::to_string(robot_->forklift_commands_clamped())});
  }
  return d;
}

void SimSource::Send(const Event& event) {
  if (event.kind == EventKind::kForkliftCommand) {
    const auto* cmd = std::get_if<msgs::ForkliftCommand>(&event.payload);
    if (!cmd || !robot_->forklift()) return;
    const int before = robot_->forklift_commands_clamped();
    robot_->CommandFork(cmd->height_m);
    if (robot_->forklift_commands_clamped() > before && before < 10) {
      mbot::log::Warn("sim: forklift command " + Significant(cmd->height_m, 4) + " m on " + event.channel +
                      " is outside [" + Significant(robot_->forklift()->options().min_height_m, 3) + ", " +
                      Significant(robot_->forklift()->options().max_height_m, 3) + "] m: clamped");
    }
    return;
  }
  if (event.kind != EventKind::kMotorCommand) return;
  const auto* cmd = std::get_if<MotorCommand>(&event.payload);
  if (!cmd || cmd->kind != MotorCommand::Kind::kVelocity) return;
  if (!robot_->Command(cmd->velocity.v_m_s, cmd->velocity.w_rad_s)) {
    mbot::log::WarnOnce("sim:command_refused",
                        "sim: velocity command (" + Significant(cmd->velocity.v_m_s, 4) + " m/s, " +
                            Significant(cmd->velocity.w_rad_s, 4) + " rad/s) on " + event.channel +
                            " refused: not finite (the robot stops), or beyond twice the firmware's limits "
                            "(max_command_v_m_s, max_command_w_rad_s: the last good one holds); "
                            "further ones are counted");
  }
}

void RegisterSimSource() {
  if (msgs::FindSourceType("sim")) return;
  msgs::RegisterSourceType(
      {"sim",
       "the simulated MBot on a world (.arena, or a map whose unknown and occupied cells are walls); its keys "
       "are the simulator's",
       [](const std::string& path) { return EndsWith(path, ".arena"); }, 0,
       [](config::Section& s, SourceOptions* o) { o->extra = ParseSimSourceOptions(s); },
       [](const SourceOptions& o) -> std::unique_ptr<msgs::Source> {
         const auto* sim = std::any_cast<SimSourceOptions>(&o.extra);
         return std::make_unique<SimSource>(o, sim ? *sim : SimSourceOptions{});
       }});
}

}  // namespace mbot::sim
