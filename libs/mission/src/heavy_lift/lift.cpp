// Heavy Lift, lift and place: tines up with the crate on them (or a miss: down, back off, try
// again), tines down to set it on the other.
#include <algorithm>
#include <cmath>

#include "heavy_lift_task.hpp"
#include "mbot/common/strings.hpp"

namespace mbot::mission::heavy_lift {

bool HeavyLiftTask::Lift(Mission& m) {
  m.Hold();
  const std::optional<ForkliftState>& f = m.forklift();
  const bool up = f && std::abs(f->height_m - o_.carry_height_m) < 0.003;
  if (f && f->carrying && f->crate_id == target() && up) {
    ++lifted_;
    carried_ = target();
    carry_offset_ = o_.fork_tip_x_m - std::max(inserted_, 0.0) + 0.5 * o_.crate_side_m;
    crates_[carried_].ForgetBefore(m.now_us() + 1);  // it moves with the robot now
    StartOut(m, "lifted " + std::to_string(carried_));
  } else if (up || (m.now_us() - phase_us_) * 1e-6 > 10.0) {
    // Up without it: the tines missed the slot. Down, back off, try again.
    Fork(m, 0.0);
    if (++attempts_ >= o_.max_attempts) {
      Fail(m, "could not engage " + Name() + " in " + std::to_string(attempts_) + " tries");
      return false;
    }
    StartOut(m, "missed " + Name() + "; backing off to try again");
  }
  return false;
}

bool HeavyLiftTask::SetDown(Mission& m) {
  m.Hold();
  const std::optional<ForkliftState>& f = m.forklift();
  if (f && !f->carrying) {
    ++stacked_;
    just_set_down_ = true;
    crates_[carried_].ForgetBefore(m.now_us() + 1);  // where it is now: to be seen again
    carried_ = -1;
    StartOut(m, "set down");
  } else if ((m.now_us() - phase_us_) * 1e-6 > 10.0) {
    Fail(m, "the forklift still carries " + std::to_string(carried_) + " 10 s after lowering");
  }
  return false;
}

}  // namespace mbot::mission::heavy_lift
