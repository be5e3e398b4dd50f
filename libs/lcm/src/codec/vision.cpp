// The vision family: mbot_apriltag_array_t (as the botlab's publisher sends it) and mbot_image_t.
#include "codec.hpp"
#include "mbot_lcm_msgs/mbot_apriltag_array_t.hpp"
#include "mbot_nav_msgs/mbot_image_t.hpp"

namespace mbot::lcmio::lcm_adapter {

void AddVisionTypes(TypeTable& t) {
  t.Add(mbot_lcm_msgs::mbot_apriltag_array_t::getHash(), "mbot_apriltag_array_t", kCurrent,
        [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
          // array_size follows utime; each detection is an int32 id and a pose3D_t (8 + 3·4 + 3·4 + 4·4).
          if (!CheckCount(d, n, 16, 4 + 48, "array_size", err)) return false;
          mbot_lcm_msgs::mbot_apriltag_array_t m{};
          if (!DecodeExact(d, n, &m, err)) return false;
          TagSightings out;
          for (const auto& t : m.detections) {
            const auto& p = t.pose;
            const double q[4] = {p.angles_quat[0], p.angles_quat[1], p.angles_quat[2], p.angles_quat[3]};
            const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
            if (!Finite(p.x, p.y, p.z) || !std::isfinite(norm) || std::abs(norm - 1.0) > 1e-3) {
              *err =
                  "tag " + std::to_string(t.tag_id) + ": non-finite position or a quaternion that is not of unit norm";
              return false;
            }
            // The botlab's publisher: millimetres; quaternion x, y, z, w.
            TagSighting seen;  // a pose only: this message has no image coordinates
            seen.id = t.tag_id;
            seen.x_m = p.x * 1e-3, seen.y_m = p.y * 1e-3, seen.z_m = p.z * 1e-3;
            seen.qw = q[3] / norm, seen.qx = q[0] / norm, seen.qy = q[1] / norm, seen.qz = q[2] / norm;
            out.tags.push_back(std::move(seen));
          }
          ev->kind = EventKind::kTagSightings;
          ev->stamp_us = m.utime;
          ev->payload = std::move(out);
          return true;
        });
  t.Add(mbot_nav_msgs::mbot_image_t::getHash(), "mbot_image_t", kOwn,
        [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
          // num_bytes follows utime, width and height.
          if (!CheckCount(d, n, 24, 1, "num_bytes", err)) return false;
          mbot_nav_msgs::mbot_image_t m{};
          if (!DecodeExact(d, n, &m, err)) return false;
          if (m.width < 1 || m.height < 1 || m.width > 8192 || m.height > 8192 ||
              static_cast<int64_t>(m.width) * m.height != m.num_bytes) {
            *err = "a " + std::to_string(m.width) + " x " + std::to_string(m.height) + " image with " +
                   std::to_string(m.num_bytes) + " bytes";
            return false;
          }
          CameraFrame f;
          f.width = m.width, f.height = m.height;
          f.pixels = std::make_shared<const std::vector<uint8_t>>(m.data.begin(), m.data.end());
          f.name = "mbot_image_t";
          ev->kind = EventKind::kCameraFrame;
          ev->stamp_us = m.utime;
          ev->payload = std::move(f);
          return true;
        });
}

bool Encoder::Tags(const Event& ev, const TagSightings& tags) {
  // As the botlab's publisher sends it: the camera frame in millimetres, roll-pitch-yaw in degrees
  // (its XYZ convention), the quaternion as x, y, z, w.
  mbot_lcm_msgs::mbot_apriltag_array_t m{};
  m.utime = ev.stamp_us;
  for (const TagSighting& s : tags.tags) {
    mbot_lcm_msgs::mbot_apriltag_t t{};
    t.tag_id = s.id;
    t.pose.utime = ev.stamp_us;
    t.pose.x = static_cast<float>(s.x_m * 1e3), t.pose.y = static_cast<float>(s.y_m * 1e3);
    t.pose.z = static_cast<float>(s.z_m * 1e3);
    const double w = s.qw, x = s.qx, y = s.qy, z = s.qz;  // rotation matrix entries from the quaternion
    const double r00 = 1 - 2 * (y * y + z * z), r10 = 2 * (x * y + w * z), r20 = 2 * (x * z - w * y);
    const double r21 = 2 * (y * z + w * x), r22 = 1 - 2 * (x * x + y * y);
    const double deg = 180.0 / M_PI;
    t.pose.angles_rpy[0] = static_cast<float>(std::atan2(r21, r22) * deg);
    t.pose.angles_rpy[1] = static_cast<float>(std::atan2(-r20, std::hypot(r00, r10)) * deg);
    t.pose.angles_rpy[2] = static_cast<float>(std::atan2(r10, r00) * deg);
    t.pose.angles_quat[0] = static_cast<float>(x), t.pose.angles_quat[1] = static_cast<float>(y);
    t.pose.angles_quat[2] = static_cast<float>(z), t.pose.angles_quat[3] = static_cast<float>(w);
    m.detections.push_back(t);
  }
  m.array_size = static_cast<int32_t>(m.detections.size());
  return Put(m);
}

bool Encoder::Frame(const Event& ev, const CameraFrame& f) {
  // mbot_image_t is grey: a colour frame has no LCM message.
  if (f.channels != 1 || !f.pixels || f.pixels->size() != static_cast<size_t>(f.width) * f.height) return false;
  mbot_nav_msgs::mbot_image_t m{};
  m.utime = ev.stamp_us;
  m.width = f.width, m.height = f.height;
  m.num_bytes = static_cast<int32_t>(f.pixels->size());
  m.data.assign(f.pixels->begin(), f.pixels->end());
  return Put(m);
}

}  // namespace mbot::lcmio::lcm_adapter
