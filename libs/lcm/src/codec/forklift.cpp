// The forklift family (mbot_nav's own types, lcmtypes/mbot_nav): its command and its status.
#include "codec.hpp"
#include "mbot_nav_msgs/mbot_forklift_cmd_t.hpp"
#include "mbot_nav_msgs/mbot_forklift_status_t.hpp"

namespace mbot::lcmio::lcm_adapter {

void AddForkliftTypes(TypeTable& t) {
  t.Add(mbot_nav_msgs::mbot_forklift_cmd_t::getHash(), "mbot_forklift_cmd_t", kOwn,
        [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
          mbot_nav_msgs::mbot_forklift_cmd_t m{};
          if (!DecodeExact(d, n, &m, err)) return false;
          if (!std::isfinite(m.height)) {
            *err = "a height that is not a finite number";
            return false;
          }
          ev->kind = EventKind::kForkliftCommand;
          ev->stamp_us = m.utime;
          ev->payload = ForkliftCommand{m.height};
          return true;
        });
  t.Add(mbot_nav_msgs::mbot_forklift_status_t::getHash(), "mbot_forklift_status_t", kOwn,
        [](const std::string&, const uint8_t* d, size_t n, const ChannelRoles&, Event* ev, std::string* err) {
          mbot_nav_msgs::mbot_forklift_status_t m{};
          if (!DecodeExact(d, n, &m, err)) return false;
          if (!std::isfinite(m.height) || !std::isfinite(m.target) || m.crate_id < -1) {
            *err = "a height or target that is not finite, or a crate id below -1";
            return false;
          }
          ev->kind = EventKind::kForkliftStatus;
          ev->stamp_us = m.utime;
          ev->payload = ForkliftStatus{m.height, m.target, m.crate_id, m.carrying != 0};
          return true;
        });
}

bool Encoder::Forklift(const Event& ev, const ForkliftCommand& c) {
  mbot_nav_msgs::mbot_forklift_cmd_t m{};
  m.utime = ev.stamp_us;
  m.height = static_cast<float>(c.height_m);
  return Put(m);
}

bool Encoder::ForkliftState(const Event& ev, const ForkliftStatus& f) {
  mbot_nav_msgs::mbot_forklift_status_t m{};
  m.utime = ev.stamp_us;
  m.height = static_cast<float>(f.height_m), m.target = static_cast<float>(f.target_m);
  m.crate_id = f.crate_id;
  m.carrying = f.carrying;
  return Put(m);
}

}  // namespace mbot::lcmio::lcm_adapter
