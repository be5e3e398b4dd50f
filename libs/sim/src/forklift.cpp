#include "mbot/sim/forklift.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace mbot::sim {
namespace {

using motion::Pose2D;

constexpr double kEps = 1e-9;

void Require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("forklift: " + what);
}

}  // namespace

Forklift::Forklift(World* world, const ForkliftOptions& options) : world_(world), o_(options) {
  Require(world_ != nullptr, "no world");
  Require(o_.min_height_m >= 0 && o_.max_height_m > o_.min_height_m, "heights must satisfy 0 <= min < max");
  Require(o_.speed_m_s > 0, "speed_m_s must be positive");
  Require(o_.tip_x_m > 0 && o_.tine_length_m > 0 && o_.tine_length_m <= o_.tip_x_m,
          "tip_x_m and tine_length_m must be positive, the tines no longer than tip_x_m");
  Require(o_.slot_m > 0 && o_.engage_depth_m > 0 && o_.engage_depth_m < o_.tine_length_m,
          "slot_m must be positive and engage_depth_m in (0, tine_length_m)");
  Require(o_.engage_lateral_m >= 0 && o_.engage_heading_deg >= 0 && o_.engage_heading_deg < 45,
          "engage tolerances must be >= 0 (heading below 45 degrees)");
  Require(o_.lift_clear_m >= 0 && o_.stack_tolerance_m >= 0, "lift_clear_m and stack_tolerance_m must be >= 0");
  Require(o_.status_rate_hz > 0, "status_rate_hz must be positive");
  height_ = target_ = o_.min_height_m;
}

bool Forklift::Command(double height_m) {
  const double h = std::isfinite(height_m) ? std::clamp(height_m, o_.min_height_m, o_.max_height_m) : height_;
  target_ = h;
  return h != height_m;
}

// The face the robot heads into is the one square to its heading (of the four, the nearest); the
// depth is how far the tips are past that face.
Forklift::Entry Forklift::EntryInto(const Crate& crate, const Pose2D& pose) const {
  Entry e;
  const Pose2D tip = pose.Compose({o_.tip_x_m, 0.0, 0.0});
  const double a = motion::WrapAngle(pose.theta - crate.pose.theta);
  const double k = std::round(a / (0.5 * M_PI));
  const double heading_error = a - k * 0.5 * M_PI;
  const double ux = std::cos(crate.pose.theta + k * 0.5 * M_PI), uy = std::sin(crate.pose.theta + k * 0.5 * M_PI);
  const double half = (static_cast<long>(std::abs(k)) % 2 == 0) ? 0.5 * crate.width_m : 0.5 * crate.depth_m;
  e.depth_m = (tip.x - crate.pose.x) * ux + (tip.y - crate.pose.y) * uy + half;
  e.inside = crate.DistanceTo(tip.x, tip.y) <= 0.0 && height_ >= crate.z_m - kEps && height_ < crate.top_m();
  const double lateral =
      std::abs(-(crate.pose.x - pose.x) * std::sin(pose.theta) + (crate.pose.y - pose.y) * std::cos(pose.theta));
  e.aligned = height_ <= crate.z_m + o_.slot_m + kEps && lateral <= o_.engage_lateral_m &&
              std::abs(heading_error) <= o_.engage_heading_deg * M_PI / 180.0;
  return e;
}

bool Forklift::CarriedCrateHits(const Crate& carried) const {
  for (const auto& [x, y] : carried.Outline(0.01)) {
    if (world_->WallsClearanceAt(x, y) <= 0.0) return true;
  }
  const std::vector<Crate>& crates = world_->crates();
  for (size_t i = 0; i < crates.size(); ++i) {
    if (static_cast<int>(i) == engaged_ || crates[i].carried) continue;
    if (crates[i].top_m() > carried.z_m + kEps && carried.Overlaps(crates[i])) return true;
  }
  return false;
}

ForkContact Forklift::Check(const Pose2D& from, const Pose2D& to) const {
  const std::vector<Crate>& crates = world_->crates();
  for (size_t i = 0; i < crates.size(); ++i) {
    const Crate& c = crates[i];
    if (c.carried) continue;
    const Entry now = EntryInto(c, from), next = EntryInto(c, to);
    if (static_cast<int>(i) == engaged_) {
      if (next.depth_m > o_.tine_length_m && next.depth_m > now.depth_m) return ForkContact::kFullyIn;
      continue;
    }
    // Into a crate other than by its slot, or deeper into one the tips are already stuck in.
    if (next.inside && !next.aligned && (!now.inside || next.depth_m > now.depth_m)) return ForkContact::kHit;
  }
  if (carrying()) {
    Crate moved = crates[engaged_];
    moved.pose = to.Compose(carry_offset_);
    Crate before = crates[engaged_];
    before.pose = from.Compose(carry_offset_);
    if (CarriedCrateHits(moved) && !CarriedCrateHits(before)) return ForkContact::kHit;
  }
  return ForkContact::kFree;
}

bool Forklift::Step(double dt_s, const Pose2D& pose) {
  const double travel = o_.speed_m_s * dt_s;
  height_ += std::clamp(target_ - height_, -travel, travel);
  if (engaged_ < 0) {
    const std::vector<Crate>& crates = world_->crates();
    for (size_t i = 0; i < crates.size(); ++i) {
      if (crates[i].carried) continue;
      const Entry e = EntryInto(crates[i], pose);
      if (e.inside && e.aligned && e.depth_m >= o_.engage_depth_m) {
        engaged_ = static_cast<int>(i);
        return true;
      }
    }
    return false;
  }
  Crate c = world_->crates()[engaged_];
  if (!c.carried) {
    if (EntryInto(c, pose).depth_m < 0.0) {  // backed out: the tines are free
      engaged_ = -1;
      return true;
    }
    height_ = std::max(height_, c.z_m);  // the tines stay in the slot: they rest on what the crate stands on
    if (height_ < c.z_m + o_.slot_m - kEps) return false;
    c.carried = true;  // the tines meet the slot's top: the crate comes up with them
    c.on_id = -1;
    carry_offset_ = pose.Inverse().Compose(c.pose);
    world_->SetCrate(engaged_, c);
    return true;
  }
  c.pose = pose.Compose(carry_offset_);
  c.z_m = height_ - o_.slot_m;
  const bool lifted_now = !c.lifted && c.z_m >= o_.lift_clear_m - kEps;  // a change to report
  c.lifted = c.lifted || lifted_now;
  double support = 0.0;  // what the crate would rest on
  const std::vector<Crate>& crates = world_->crates();
  for (size_t i = 0; i < crates.size(); ++i) {
    if (static_cast<int>(i) != engaged_ && !crates[i].carried && crates[i].top_m() <= c.z_m + o_.slot_m + kEps &&
        c.Overlaps(crates[i]))
      support = std::max(support, crates[i].top_m());
  }
  if (c.z_m >= support - kEps) {
    world_->SetCrate(engaged_, c);
    return lifted_now;
  }
  SetDown(&c, pose);
  return true;
}

void Forklift::SetDown(Crate* c, const Pose2D& pose) {
  const std::vector<Crate>& crates = world_->crates();
  int below = -1;  // the highest crate the footprint overlaps
  for (size_t i = 0; i < crates.size(); ++i) {
    if (static_cast<int>(i) == engaged_ || crates[i].carried || !c->Overlaps(crates[i])) continue;
    if (crates[i].top_m() <= c->z_m + o_.slot_m + kEps && (below < 0 || crates[i].top_m() > crates[below].top_m()))
      below = static_cast<int>(i);
  }
  c->carried = false;
  if (below < 0) {
    c->z_m = 0.0;
    world_->SetCrate(engaged_, *c);
    return;
  }
  const Crate& b = crates[below];
  const double off = std::hypot(c->pose.x - b.pose.x, c->pose.y - b.pose.y);
  if (off <= o_.stack_tolerance_m) {
    c->z_m = b.top_m();
    c->on_id = b.id;
    world_->SetCrate(engaged_, *c);
    return;
  }
  // Off-centre: it tips over the side it overhangs and lands on the floor beside the crate below.
  double dx = c->pose.x - b.pose.x, dy = c->pose.y - b.pose.y;
  if (off < 1e-6) dx = std::cos(pose.theta), dy = std::sin(pose.theta);
  const double n = std::hypot(dx, dy);
  const double reach = 0.5 * (std::hypot(b.width_m, b.depth_m) + std::hypot(c->width_m, c->depth_m)) + 0.005;
  c->pose.x = b.pose.x + dx / n * reach;
  c->pose.y = b.pose.y + dy / n * reach;
  c->z_m = 0.0;
  c->fell = true;
  world_->SetCrate(engaged_, *c);
  engaged_ = -1;
}

}  // namespace mbot::sim
