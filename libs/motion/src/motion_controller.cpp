#include "mbot/motion/motion_controller.hpp"

#include <algorithm>
#include <cmath>
#include <tuple>

namespace mbot::motion {
namespace {

double Clamp(double x, double limit) { return std::clamp(x, -limit, limit); }

double Dist(const Pose2D& a, const Pose2D& b) { return std::hypot(b.x - a.x, b.y - a.y); }

// Direction of the point (x, y) seen from `p`, relative to its heading.
double Bearing(const Pose2D& p, double x, double y) { return WrapAngle(std::atan2(y - p.y, x - p.x) - p.theta); }

}  // namespace

MotionController::MotionController(const MotionControllerOptions& options) : options_(options) {
  progress_.arrived = true;  // nothing to do until SetPath
}

void MotionController::SetPath(const std::vector<Pose2D>& waypoints) {
  waypoints_ = waypoints;
  phase_ = waypoints_.empty() ? Phase::kSettle : Phase::kFollow;
  target_ = 0;
  path_.clear();
  arc_.clear();
  segment_ = 0;
  projection_m_ = 0.0;
  progress_ = ControllerProgress{0, waypoints_.size(), 0.0, false};
}

VelocityCommand MotionController::Update(const Pose2D& pose, double dt_s) {
  if (!waypoints_.empty()) progress_.distance_to_goal_m = Dist(pose, waypoints_.back());
  if (progress_.arrived || dt_s <= 0.0) return last_;  // last_ is zero once arrived
  const VelocityCommand target = Target(pose);
  const double dv = options_.max_accel_m_s2 * dt_s;
  const double dw = options_.max_angular_accel_rad_s2 * dt_s;
  // Prefer the largest λ ∈ [0, 1] for which λ·target is reachable from the last command: it keeps
  // the curvature ω/v the steering law asked for, so the robot drives the intended arc while it
  // speeds up (clamping v and ω separately would turn far too sharply when starting from rest).
  double lo = 0.0, hi = 1.0;
  for (const auto& [t, c, d] :
       {std::tuple{target.v_m_s, last_.v_m_s, dv}, std::tuple{target.w_rad_s, last_.w_rad_s, dw}}) {
    if (t == 0.0) {
      if (std::abs(c) > d) lo = INFINITY;
      continue;
    }
    const double a = (c - d) / t, b = (c + d) / t;
    lo = std::max(lo, std::min(a, b));
    hi = std::min(hi, std::max(a, b));
  }
  if (lo <= hi) {
    last_ = {hi * target.v_m_s, hi * target.w_rad_s};
  } else {  // no scaling fits (e.g. still braking): limit each component on its own
    last_.v_m_s = last_.v_m_s + Clamp(target.v_m_s - last_.v_m_s, dv);
    last_.w_rad_s = last_.w_rad_s + Clamp(target.w_rad_s - last_.w_rad_s, dw);
  }
  last_ = {Clamp(last_.v_m_s, options_.max_speed_m_s), Clamp(last_.w_rad_s, options_.max_turn_rate_rad_s)};
  // A zero target is reached exactly (λ = 1, or x + (-x) == 0), so the ramp down ends on a stop.
  progress_.arrived = phase_ == Phase::kSettle && last_.v_m_s == 0.0 && last_.w_rad_s == 0.0;
  progress_.waypoint_index = progress_.arrived ? waypoints_.size() : target_;
  return last_;
}

VelocityCommand MotionController::Target(const Pose2D& pose) {
  if (phase_ == Phase::kFollow) {
    VelocityCommand cmd;
    const size_t last = waypoints_.size() - 1;
    const double d_last = Dist(pose, waypoints_[last]);
    // A final pose a few centimetres behind the robot (it overshot, or stopped short of a correction):
    // back up to it rather than turn round, drive two centimetres and turn back.
    if (last == 0 && d_last < options_.reverse_within_m && d_last >= options_.final_tolerance_m &&
        std::abs(Bearing(pose, waypoints_[last].x, waypoints_[last].y)) > M_PI / 2) {
      const double e = WrapAngle(Bearing(pose, waypoints_[last].x, waypoints_[last].y) - M_PI);
      if (std::abs(e) > options_.turn_in_place_rad) return {0.0, TurnRate(e)};
      return {-Speed(d_last) * std::cos(e), TurnRate(e)};
    }
    if (options_.kind == ControllerKind::kPurePursuit) {
      if (PurePursuit(pose, &cmd)) return cmd;
    } else {
      while (target_ < last && Dist(pose, waypoints_[target_]) < PassTolerance(target_)) ++target_;
      if (target_ < last || Dist(pose, waypoints_[last]) >= options_.final_tolerance_m) {
        return DriveTowards(pose, waypoints_[target_].x, waypoints_[target_].y, RtrStopDistance(pose));
      }
    }
    // Within final tolerance: position is done for good, only the heading is left.
    target_ = waypoints_.size() - 1;
    phase_ = Phase::kAlign;
  }
  if (phase_ == Phase::kAlign) {
    const double e = WrapAngle(waypoints_.back().theta - pose.theta);
    if (std::abs(e) > options_.final_heading_tolerance_rad) return {0.0, TurnRate(e)};
    phase_ = Phase::kSettle;
  }
  return {};
}

// On a final line, the leg ends this close before the goal: the ramp to zero covers the rest.
constexpr double kFinalLineStopM = 0.004;

bool MotionController::PurePursuit(const Pose2D& pose, VelocityCommand* cmd) {
  if (path_.empty()) {  // the polyline starts where the robot is when it starts following
    path_.push_back(pose);
    path_.insert(path_.end(), waypoints_.begin(), waypoints_.end());
    arc_.assign(1, 0.0);
    for (size_t i = 1; i < path_.size(); ++i) arc_.push_back(arc_.back() + Dist(path_[i - 1], path_[i]));
  }
  const double lookahead = options_.lookahead_m;
  const double total = arc_.back();
  // Project onto the nearest segment among those starting within one look-ahead of the current
  // projection: progress never runs backwards nor jumps to a later pass of a self-crossing path.
  double best = INFINITY;
  const double window_end = projection_m_ + lookahead;
  for (size_t k = segment_, first = segment_; k + 1 < path_.size() && (k == first || arc_[k] <= window_end); ++k) {
    const Pose2D& a = path_[k];
    const double dx = path_[k + 1].x - a.x, dy = path_[k + 1].y - a.y;
    const double len = arc_[k + 1] - arc_[k];
    const double t = len > 0.0 ? std::clamp(((pose.x - a.x) * dx + (pose.y - a.y) * dy) / (len * len), 0.0, 1.0) : 0.0;
    const double d = std::hypot(a.x + t * dx - pose.x, a.y + t * dy - pose.y);
    if (d < best) {
      best = d;
      segment_ = k;
      projection_m_ = arc_[k] + t * len;
    }
  }
  target_ = segment_;  // segment k ends at waypoint k
  const Pose2D& end = waypoints_.back();
  // The last leg is finished along its own line: the look-ahead point goes on past the goal along
  // the leg instead of stopping on it (so the heading does not swing in the last centimetres), and
  // the robot brakes at max_accel to stop on the goal, in the time a constant deceleration takes
  // rather than the long tail of a speed proportional to the distance. (A circuit's last leg runs
  // in the start's heading, so it also arrives facing the right way.)
  const Pose2D& before = path_[path_.size() - 2];
  const bool final_line = segment_ + 2 == path_.size() && Dist(before, end) > lookahead;
  const double phi = std::atan2(end.y - before.y, end.x - before.x);
  const double ahead = (end.x - pose.x) * std::cos(phi) + (end.y - pose.y) * std::sin(phi);
  const double aside = -(end.x - pose.x) * std::sin(phi) + (end.y - pose.y) * std::cos(phi);
  // Level with the goal, or so near that it lies more to the side than ahead: Settled judges how well.
  if (final_line && ahead <= std::max(kFinalLineStopM, std::abs(aside))) return false;
  if (!final_line && projection_m_ + lookahead >= total && Dist(pose, end) < options_.final_tolerance_m) return false;
  const double s_goal = final_line ? projection_m_ + lookahead : std::min(projection_m_ + lookahead, total);

  Pose2D goal;
  if (s_goal > total) {
    goal = end;
    goal.x += (s_goal - total) * std::cos(phi);
    goal.y += (s_goal - total) * std::sin(phi);
  } else {
    size_t j = segment_;
    while (j + 2 < path_.size() && arc_[j + 1] < s_goal) ++j;
    const double len = arc_[j + 1] - arc_[j];
    const double u = len > 0.0 ? std::clamp((s_goal - arc_[j]) / len, 0.0, 1.0) : 1.0;
    goal = Interpolate(path_[j], path_[j + 1], u);  // its heading is not used
  }
  const Pose2D local = pose.Inverse().Compose(goal);
  const double e = std::atan2(local.y, local.x);
  if (std::abs(e) > options_.turn_in_place_rad) {
    *cmd = {0.0, TurnRate(e)};
    return true;
  }
  const double chord2 = local.x * local.x + local.y * local.y;
  // The arc through the look-ahead point tangent to the heading. The chord is used rather than
  // lookahead_m so the law stays right when the point is clipped at the end or the robot is off
  // the path; near the end v ∝ chord, which keeps ω = v·κ bounded.
  const double kappa = chord2 > 0.0 ? 2.0 * local.y / chord2 : 0.0;
  double v = final_line ? std::min(options_.max_speed_m_s, std::sqrt(2.0 * options_.max_accel_m_s2 * ahead))
                        : Speed(std::sqrt(chord2) + total - s_goal);
  if (std::abs(kappa) * v > options_.max_turn_rate_rad_s) v = options_.max_turn_rate_rad_s / std::abs(kappa);
  *cmd = {v, v * kappa};
  return true;
}

double MotionController::PassTolerance(size_t k) const {
  // The first waypoint's leg is whatever the robot drives to it (a replanned path starts beside
  // the robot, in any direction): only a corner between two of the path's legs is held.
  if (options_.corner_tolerance_m <= 0.0 || k == 0 || k + 1 >= waypoints_.size())
    return options_.intermediate_tolerance_m;
  const Pose2D &a = waypoints_[k - 1], &b = waypoints_[k], &c = waypoints_[k + 1];
  if (Dist(a, b) == 0.0 || Dist(b, c) == 0.0) return options_.intermediate_tolerance_m;
  const double turn = WrapAngle(std::atan2(c.y - b.y, c.x - b.x) - std::atan2(b.y - a.y, b.x - a.x));
  return std::abs(turn) > options_.turn_in_place_rad ? options_.corner_tolerance_m : options_.intermediate_tolerance_m;
}

double MotionController::RtrStopDistance(const Pose2D& pose) const {
  double d = Dist(pose, waypoints_[target_]);
  double heading = std::atan2(waypoints_[target_].y - pose.y, waypoints_[target_].x - pose.x);
  for (size_t j = target_; j + 1 < waypoints_.size(); ++j) {
    const Pose2D& a = waypoints_[j];
    const Pose2D& b = waypoints_[j + 1];
    const double len = Dist(a, b);
    if (len == 0.0) continue;
    const double next = std::atan2(b.y - a.y, b.x - a.x);
    if (std::abs(WrapAngle(next - heading)) > options_.turn_in_place_rad) break;  // stops to turn at a
    d += len;
    heading = next;
  }
  return d;
}

VelocityCommand MotionController::DriveTowards(const Pose2D& pose, double gx, double gy, double stop_distance_m) const {
  const double e = Bearing(pose, gx, gy);
  if (std::abs(e) > options_.turn_in_place_rad) return {0.0, TurnRate(e)};
  return {Speed(stop_distance_m) * std::cos(e), TurnRate(e)};
}

double MotionController::Speed(double stop_distance_m) const {
  const double d = std::max(stop_distance_m, 0.0);
  return std::min({options_.max_speed_m_s, options_.k_distance * d, std::sqrt(2.0 * options_.max_accel_m_s2 * d)});
}

double MotionController::TurnRate(double heading_error_rad) const {
  const double e = std::abs(heading_error_rad);
  // The square-root term is the rate from which max_angular_accel still stops within e.
  const double w = std::min(
      {options_.k_bearing * e, options_.max_turn_rate_rad_s, std::sqrt(2.0 * options_.max_angular_accel_rad_s2 * e)});
  return std::copysign(w, heading_error_rad);
}

Pose2D StepUnicycle(const Pose2D& p, const VelocityCommand& c, double dt_s) {
  // The arc's chord has length ds·sin(dθ/2)/(dθ/2) and points along the mid-arc heading; this form
  // stays exact as ω → 0, unlike the v/ω radius form.
  const double half = 0.5 * c.w_rad_s * dt_s;
  const double ds = c.v_m_s * dt_s;
  const double chord = std::abs(half) < 1e-9 ? ds : ds * std::sin(half) / half;
  const double mid = p.theta + half;
  return {p.x + chord * std::cos(mid), p.y + chord * std::sin(mid), WrapAngle(p.theta + 2.0 * half)};
}

}  // namespace mbot::motion
