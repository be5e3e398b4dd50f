// The pose family: pose_xyt_t / odometry_t / pose2D_t (their meaning from the channel's role),
// paths and particles.
#include "codec.hpp"
#include "mbot_lcm_msgs/pose2D_t.hpp"
#include "mbot_legacy/particles_t.hpp"
#include "mbot_legacy/pose_xyt_t.hpp"
#include "mbot_legacy/robot_path_t.hpp"

namespace mbot::lcmio::lcm_adapter {

namespace {

bool DecodePose(const std::string& channel, const uint8_t* d, size_t n, const ChannelRoles& roles, Event* ev,
                std::string* err) {
  mbot_legacy::pose_xyt_t m{};
  if (!DecodeExact(d, n, &m, err)) return false;
  if (!Finite(m.x, m.y, m.theta)) {
    *err = "non-finite pose";
    return false;
  }
  ev->stamp_us = m.utime;
  ev->payload = msgs::Pose2D{m.x, m.y, m.theta};
  if (In(roles.ground_truth, channel))
    ev->kind = EventKind::kGroundTruth;
  else if (In(roles.odometry, channel))
    ev->kind = EventKind::kOdometry;
  else if (In(roles.reference_pose, channel))
    ev->kind = EventKind::kReferencePose;
  else if (In(roles.pose_estimate, channel))
    ev->kind = EventKind::kPoseEstimate;
  else
    ev->kind = EventKind::kOther;
  return true;
}

}  // namespace

void AddPoseTypes(TypeTable& t) {
  t.Add(mbot_legacy::pose_xyt_t::getHash(), "pose_xyt_t", kLegacy, DecodePose);
  t.Add(mbot_legacy::pose_xyt_t::getHash(), "odometry_t", kW23, DecodePose);
  t.Add(mbot_lcm_msgs::pose2D_t::getHash(), "pose2D_t", kCurrent, DecodePose);

  t.Add(mbot_legacy::particles_t::getHash(), "particles_t", kLegacy,
        Other<mbot_legacy::particles_t>(16, 48, "num_particles"));
  t.Add(mbot_legacy::particles_t::getHash(), "particles_t", kW23, nullptr);
  t.Add(mbot_legacy::particles_t::getHash(), "particles_t", kCurrent, nullptr);
  t.Add(mbot_legacy::robot_path_t::getHash(), "robot_path_t", kLegacy,
        [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
          if (!CheckCount(d, n, 16, 20, "path_length", err)) return false;
          mbot_legacy::robot_path_t m{};
          if (!DecodeExact(d, n, &m, err)) return false;
          Path path;
          for (const auto& p : m.path) {
            if (!Finite(p.x, p.y, p.theta)) {
              *err = "non-finite pose in the path";
              return false;
            }
            path.poses.push_back({p.x, p.y, p.theta});
          }
          ev->kind = EventKind::kPath;
          ev->stamp_us = m.utime;
          ev->payload = std::move(path);
          return true;
        });
  t.Add(mbot_legacy::robot_path_t::getHash(), "path2D_t", kCurrent, nullptr);
}

bool Encoder::Pose(const Event& ev, const Pose2D& p) {
  mbot_lcm_msgs::pose2D_t m{};  // every pose kind
  m.utime = ev.stamp_us;
  m.x = static_cast<float>(p.x), m.y = static_cast<float>(p.y), m.theta = static_cast<float>(p.theta);
  return Put(m);
}

bool Encoder::PathPoses(const Event& ev, const Path& path) {
  mbot_legacy::robot_path_t m{};  // = 2023+ path2D_t
  m.utime = ev.stamp_us;
  for (const Pose2D& p : path.poses) {
    m.path.push_back({ev.stamp_us, static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.theta)});
  }
  m.path_length = static_cast<int32_t>(m.path.size());
  return Put(m);
}

bool Encoder::ParticleSet(const Event& ev, const Particles& p) {
  mbot_legacy::particles_t m{};  // = 2023+ particles_t
  m.utime = ev.stamp_us;
  for (size_t i = 0; i < p.poses.size(); ++i) {
    mbot_legacy::particle_t q{};
    q.pose = {ev.stamp_us, static_cast<float>(p.poses[i].x), static_cast<float>(p.poses[i].y),
              static_cast<float>(p.poses[i].theta)};
    q.parent_pose = q.pose;
    q.weight = i < p.weights.size() ? p.weights[i] : 0.0;
    m.particles.push_back(q);
  }
  m.num_particles = static_cast<int32_t>(m.particles.size());
  return Put(m);
}

}  // namespace mbot::lcmio::lcm_adapter
