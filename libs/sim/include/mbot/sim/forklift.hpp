// The simulated MBot's forklift (Heavy Lift): a pair of tines at the front of the robot that move
// up and down at a limited speed to a commanded height, and the crates they pick up and set down.
//
// The model, in the robot frame (x ahead): the tines' tips are tip_x_m ahead of the robot's centre
// and they are tine_length_m long; their height h is the height of their upper face above the
// floor. A crate has a slot in its base, slot_m high, open on every side (the botlab's crates are
// lifted by their base), so:
//   - The tips meet a crate when they are inside its footprint with h between its underside and
//     its top. With h in the slot (z ≤ h ≤ z + slot_m), the robot heading square to a face within
//     engage_heading_deg and the robot's centre line within engage_lateral_m of the crate's centre,
//     the tines slide in; otherwise they hit the crate: a collision, and the robot stops.
//   - Once the tips are engage_depth_m inside, the crate is engaged: the robot's body no longer
//     meets it (the tines are under it) and it can slide on until the tines are fully in
//     (tine_length_m), where the robot stops (not a collision).
//   - Rising with a crate engaged, the tines reach the slot's top (h = z + slot_m) and lift it: the
//     crate is carried, its underside at h − slot_m, moving with the robot. It counts as lifted
//     once its underside is lift_clear_m above the floor. A carried crate that meets a wall, or a
//     crate whose top is above its underside, stops the robot (a collision).
//   - Lowering, the carried crate comes to rest on what is under it — the floor, or the highest
//     crate its footprint overlaps. On a crate, with the centres within stack_tolerance_m, it is
//     stacked; farther off-centre it tips off the side it overhangs and lands on the floor beside
//     (fell). Either way it is let go, and the tines slide out when the robot backs off.
// Heights are in metres above the floor, poses in the world frame.
#pragma once

#include <vector>

#include "mbot/motion/pose2d.hpp"
#include "mbot/sim/world.hpp"

namespace mbot::sim {

struct ForkliftOptions {
  bool enabled = false;  // a robot without a forklift has no tines: crates are only obstacles
  // The tips 18 cm ahead of the centre and 8 cm long: the tines reach past the MBot's 10 cm-radius
  // body, so a crate fully on them still clears the body by 2 cm at the crate's sides' corners.
  double tip_x_m = 0.18;
  double tine_length_m = 0.08;
  double min_height_m = 0.0;
  double max_height_m = 0.15;
  double speed_m_s = 0.05;  // how fast the tines move up or down
  double slot_m = 0.03;
  double engage_depth_m = 0.02;
  double engage_lateral_m = 0.02;
  double engage_heading_deg = 10.0;
  double lift_clear_m = 0.01;
  double stack_tolerance_m = 0.03;
  double status_rate_hz = 10.0;  // MBOT_FORKLIFT_STATUS
};

// What a step of the robot does to the fork and the crates.
enum class ForkContact {
  kFree,     // nothing in the way
  kFullyIn,  // the tines are fully under the engaged crate: the robot stops (no collision)
  kHit,      // the tips or the carried crate hit something: the robot stops, a collision
};

class Forklift {
 public:
  // Acts on `world`'s crates, which it moves; `world` must outlive it. Throws std::invalid_argument
  // when an option is out of range.
  Forklift(World* world, const ForkliftOptions& options);

  // The height the tines move to; outside [min_height_m, max_height_m] it is clamped into range and
  // true is returned.
  bool Command(double height_m);
  // Whether the robot may move from `from` to `to` as far as the fork is concerned (its tips and
  // the crate it carries); changes nothing.
  ForkContact Check(const motion::Pose2D& from, const motion::Pose2D& to) const;
  // After a step of `dt_s` seconds that ended at `pose`: moves the tines, engages, lifts, carries,
  // sets down. True when a crate changed its state (not just its pose while carried).
  bool Step(double dt_s, const motion::Pose2D& pose);

  double height_m() const { return height_; }
  double target_m() const { return target_; }
  // The crate under the tines (an index into the world's crates), -1 when none.
  int engaged() const { return engaged_; }
  bool carrying() const { return engaged_ >= 0 && world_->crates()[engaged_].carried; }
  const ForkliftOptions& options() const { return o_; }

 private:
  struct Entry {
    bool inside = false;   // the tips are inside the crate's footprint at a height that meets it
    bool aligned = false;  // … and in its slot, square to a face, centred
    double depth_m = 0;    // how far inside the face the tips are
  };
  Entry EntryInto(const Crate& crate, const motion::Pose2D& pose) const;
  bool CarriedCrateHits(const Crate& carried) const;
  void SetDown(Crate* crate, const motion::Pose2D& pose);

  World* world_;
  ForkliftOptions o_;
  double height_ = 0.0, target_ = 0.0;
  int engaged_ = -1;
  motion::Pose2D carry_offset_;  // the carried crate's pose in the robot frame
};

}  // namespace mbot::sim
