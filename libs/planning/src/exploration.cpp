#include "mbot/planning/exploration.hpp"

#include <cmath>
#include <algorithm>
#include <cstdio>
#include <limits>

namespace mbot::planning {
namespace {

std::string Format(const char* fmt, double a, double b, double c = 0.0) {
  char buf[160];
  std::snprintf(buf, sizeof buf, fmt, a, b, c);
  return buf;
}

// A frontier whose centroid moved this far since it was chosen has changed [m].
constexpr double kFrontierMovedM = 0.15;

}  // namespace

const char* ToString(ExplorationState s) {
  switch (s) {
    case ExplorationState::kInitializing: return "initializing";
    case ExplorationState::kExploring: return "exploring";
    case ExplorationState::kReturningHome: return "returning home";
    case ExplorationState::kCompleted: return "completed";
    case ExplorationState::kIncomplete: return "incomplete";
    case ExplorationState::kFailed: return "failed";
  }
  return "?";
}

Explorer::Explorer(const ExplorationOptions& options)
    : options_(options),
      distances_(options.distance),
      planner_(options.astar),
      home_retries_left_(options.home_retries) {
  failed_views_.radius_m = options.second_view_m;
  failed_views_.match_m = options.blacklist_radius_m;  // the same frontier as the blacklist's
}

bool Explorer::HadFailedView(const Frontier& f) const {
  return std::any_of(failed_views_.views.begin(), failed_views_.views.end(), [&](const FailedView& v) {
    return std::hypot(v.frontier_x - f.centroid_x, v.frontier_y - f.centroid_y) <= failed_views_.match_m;
  });
}

bool Explorer::IsBlacklisted(const Frontier& f, double t_s, bool* for_good) const {
  bool found = false;
  if (for_good) *for_good = false;
  for (const Blacklisted& b : blacklist_) {
    // Near a frontier given up, and not grown much since: the same one. A frontier that has grown
    // (a small one at a gap became the mouth of a corridor) is new.
    if (t_s < b.until_s && std::hypot(f.centroid_x - b.x, f.centroid_y - b.y) <= options_.blacklist_radius_m &&
        f.size() <= 2 * b.cells + options_.frontier.min_cells) {
      found = true;
      if (!for_good) return true;
      if (std::isinf(b.until_s)) *for_good = true;
    }
  }
  return found;
}

void Explorer::DropBlacklisted(double t_s) {
  frontiers_.erase(
      std::remove_if(frontiers_.begin(), frontiers_.end(), [&](const Frontier& f) { return IsBlacklisted(f, t_s); }),
      frontiers_.end());
}

bool Explorer::PathIsSafe(const motion::Pose2D& pose) const {
  if (path_.size() < 2) return true;
  // The waypoint the robot is heading to: the end of the path segment nearest to it.
  size_t next = 1;
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i + 1 < path_.size(); ++i) {
    const double ax = path_[i].x, ay = path_[i].y, bx = path_[i + 1].x, by = path_[i + 1].y;
    const double vx = bx - ax, vy = by - ay, len2 = vx * vx + vy * vy;
    const double s = len2 > 0 ? std::clamp(((pose.x - ax) * vx + (pose.y - ay) * vy) / len2, 0.0, 1.0) : 0.0;
    const double d = std::hypot(ax + s * vx - pose.x, ay + s * vy - pose.y);
    if (d < best) {
      best = d;
      next = i + 1;
    }
  }
  const double r = options_.astar.robot_radius_m;
  for (size_t i = next; i + 1 < path_.size(); ++i) {
    if (!planner_.SegmentIsClear(path_[i].x, path_[i].y, path_[i + 1].x, path_[i + 1].y, r)) return false;
  }
  return true;
}

void Explorer::Fail(const std::string& reason, ExplorationUpdate* u) {
  state_ = ExplorationState::kFailed;
  failure_reason_ = reason;
  path_.clear();
  u->new_path = true;
  u->path.clear();
  u->reason = reason;
}

bool Explorer::SelectFrontier(const mapping::OccupancyGrid& map, const motion::Pose2D& pose, double t_s,
                              ExplorationUpdate* u) {
  std::vector<int> unreachable;
  const double r = options_.astar.robot_radius_m;
  const std::vector<FrontierGoal> goals =
      RankFrontierGoals(frontiers_, pose, map, planner_, r, options_.frontier, &unreachable, failed_views_);
  for (int i : unreachable) {
    // One whose only reachable cells were seen not to resolve it (a failed viewpoint) is given up for
    // good; one with no path now, for a while.
    const bool viewed = HadFailedView(frontiers_[i]);
    blacklist_.push_back({frontiers_[i].centroid_x, frontiers_[i].centroid_y,
                          viewed ? std::numeric_limits<double>::infinity() : t_s + options_.blacklist_s,
                          frontiers_[i].size()});
  }
  for (const FrontierGoal& g : goals) {
    const Frontier& f = frontiers_[g.frontier];
    const PlanResult plan = planner_.PlanSteppingOut(pose, g.target);
    if (plan.status != PlanStatus::kFound) {
      blacklist_.push_back({f.centroid_x, f.centroid_y, t_s + options_.blacklist_s, f.size()});
      continue;
    }
    path_ = plan.path;
    target_point_ = g.target;
    target_frontier_ = motion::Pose2D{f.centroid_x, f.centroid_y, 0.0};
    target_size_ = f.size();
    ++replans_;
    u->new_path = true;
    u->path = path_;
    u->reason += (u->reason.empty() ? "" : "; ") +
                 Format("exploring a frontier of %.0f cells at (%.2f, %.2f)", f.size(), f.centroid_x, f.centroid_y) +
                 Format(" from (%.2f, %.2f)", g.target.x, g.target.y) +
                 Format(" with clearance %.2f m", plan.clearance_m, 0.0);
    return true;
  }
  return false;
}

std::vector<FrontierLeft> Explorer::FrontiersLeft(const mapping::OccupancyGrid& map, const motion::Pose2D& pose,
                                                  double t_s) {
  const std::vector<Frontier> all = FindFrontiers(map, options_.frontier);
  std::vector<int> unreachable;
  RankFrontierGoals(all, pose, map, planner_, options_.astar.robot_radius_m, options_.frontier, &unreachable,
                    failed_views_);
  std::vector<FrontierLeft> left;
  for (int i = 0; i < static_cast<int>(all.size()); ++i) {
    const bool reachable = std::find(unreachable.begin(), unreachable.end(), i) == unreachable.end();
    bool for_good = false;
    const bool blacklisted = IsBlacklisted(all[i], t_s, &for_good);
    // Seen from its target and still there, a pocket smaller than the robot is no unexplored space:
    // the robot cannot enter it, and the referee counts only what its body reaches.
    if (for_good && IsPocket(all[i], map, options_.frontier)) continue;
    left.push_back({all[i].centroid_x, all[i].centroid_y, all[i].size(), reachable, blacklisted, for_good});
  }
  return left;
}

ExplorationUpdate Explorer::Update(const mapping::OccupancyGrid& map, const motion::Pose2D& pose, double t_s) {
  ExplorationUpdate u;
  if (state_ == ExplorationState::kCompleted || state_ == ExplorationState::kIncomplete ||
      state_ == ExplorationState::kFailed) {
    u.state = state_;
    u.reason = failure_reason_;
    return u;
  }
  planner_.UpdateMap(distances_, distances_.Update(map));
  int cx, cy;
  map.WorldToCell(pose.x, pose.y, &cx, &cy);
  if (!map.IsInside(cx, cy)) {
    Fail(Format("the robot at (%.2f, %.2f) is off the map", pose.x, pose.y), &u);
    u.state = state_;
    return u;
  }
  if (state_ == ExplorationState::kInitializing) {
    home_ = options_.home.value_or(pose);
    state_ = ExplorationState::kExploring;
    u.reason = Format("home fixed at (%.2f, %.2f)", home_.x, home_.y);
  }
  const double radius = options_.astar.robot_radius_m;
  auto plan_home = [&](const std::string& why) {
    const PlanResult plan = planner_.PlanSteppingOut(pose, home_);
    if (plan.status == PlanStatus::kStartInCollision) {
      // The robot's own surroundings are not clear on this map (an early map, a wall seen late):
      // wait for the next map rather than give up.
      path_.clear();
      u.new_path = true;
      u.reason += (u.reason.empty() ? "" : "; ") +
                  std::string("robot too close to obstacles or unknown space to plan home, waiting");
      return;
    }
    if (plan.status != PlanStatus::kFound) {
      Fail(std::string("home unreachable (") + ToString(plan.status) + ")" + (why.empty() ? "" : " " + why), &u);
      return;
    }
    path_ = plan.path;
    ++replans_;
    u.new_path = true;
    u.path = path_;
    u.reason += (u.reason.empty() ? "" : "; ") + std::string("returning home") + (why.empty() ? "" : " " + why);
  };

  if (state_ == ExplorationState::kExploring) {
    frontiers_ = FindFrontiers(map, options_.frontier);
    DropBlacklisted(t_s);
    bool need = path_.empty();
    std::string why;
    if (!need && target_frontier_) {
      const Frontier* match = nullptr;
      double match_d = options_.frontier_match_m;
      for (const Frontier& f : frontiers_) {
        const double d = std::hypot(f.centroid_x - target_frontier_->x, f.centroid_y - target_frontier_->y);
        if (d <= match_d) match_d = d, match = &f;
      }
      const bool reached = std::hypot(pose.x - path_.back().x, pose.y - path_.back().y) <= options_.target_reached_m;
      if (!reached) reached_at_s_ = -1;  // pushed or drifted off: the wait starts again on return
      // What the robot saw on the way changed the frontier (part of it was resolved, its centroid
      // moved): the target chosen for the old one may not show the rest, so choose again.
      const bool changed =
          match && (match_d > kFrontierMovedM || std::abs(match->size() - target_size_) > 0.25 * target_size_);
      if (!match) {
        need = true;
        why = "target frontier explored";
      } else if (reached && changed) {
        need = true;
        why = "target frontier changed, choosing again";
      } else if (reached && reached_at_s_ < 0) {
        reached_at_s_ = t_s;  // give the map time to show what the robot sees from here
      } else if (reached && t_s - reached_at_s_ >= options_.resolve_wait_s) {
        // Standing at the target and the frontier is still there: nothing more can be seen from
        // here (unknown space the sensor cannot resolve, a gap too narrow to pass, a pocket behind a
        // wall's end). It gets one more viewpoint away from this one; still there after that, it is
        // ignored for good, unlike a frontier that was only unreachable.
        if (!HadFailedView(*match) && options_.second_view_m > 0) {
          failed_views_.views.push_back({match->centroid_x, match->centroid_y, target_point_.x, target_point_.y});
          why = "frontier unresolved at its target, trying another viewpoint";
        } else {
          blacklist_.push_back(
              {target_frontier_->x, target_frontier_->y, std::numeric_limits<double>::infinity(), target_size_});
          why = "frontier unresolved at its target, blacklisted";
        }
        need = true;
      }
    }
    if (!need && !PathIsSafe(pose)) {
      need = true;
      why = "path no longer safe on the updated map";
    }
    if (need) {
      if (!why.empty()) u.reason += (u.reason.empty() ? "" : "; ") + why;
      DropBlacklisted(t_s);  // the frontier blacklisted just now drops out of the candidates
      target_frontier_.reset();
      reached_at_s_ = -1;
      path_.clear();
      if (!SelectFrontier(map, pose, t_s, &u)) {
        if (!(planner_.DistanceAt(pose.x, pose.y) > radius) && !frontiers_.empty()) {
          // Frontiers exist but the robot cannot move on this map yet: wait for the next one.
          u.reason += (u.reason.empty() ? "" : "; ") +
                      std::string("robot too close to obstacles or unknown space to plan, waiting");
        } else {
          state_ = ExplorationState::kReturningHome;
          plan_home("(no reachable frontier left)");
        }
      }
    }
  } else if (state_ == ExplorationState::kReturningHome) {
    const double off = std::hypot(pose.x - home_.x, pose.y - home_.y);
    // What the robot saw on the way home (or a frontier whose blacklisting ran out) may have opened
    // a frontier it can reach: it goes back to exploring rather than stopping early.
    frontiers_ = FindFrontiers(map, options_.frontier);
    DropBlacklisted(t_s);
    if (off > options_.home_tolerance_m && !frontiers_.empty() && SelectFrontier(map, pose, t_s, &u)) {
      state_ = ExplorationState::kExploring;
      u.reason = "a frontier is reachable again; " + u.reason;
    } else if (off <= options_.home_tolerance_m) {
      path_.clear();
      u.new_path = true;
      left_ = FrontiersLeft(map, pose, t_s);
      // Frontiers given up only for a while (no path to them then) that can be reached now: forget
      // them and explore again, rather than end incomplete.
      const bool retry = home_retries_left_ > 0 && std::any_of(left_.begin(), left_.end(), [](const FrontierLeft& f) {
                           return f.reachable && !f.unresolved;
                         });
      if (retry) {
        --home_retries_left_;
        blacklist_.erase(std::remove_if(blacklist_.begin(), blacklist_.end(),
                                        [](const Blacklisted& b) { return std::isfinite(b.until_s); }),
                         blacklist_.end());
        frontiers_ = FindFrontiers(map, options_.frontier);
        DropBlacklisted(t_s);
        if (SelectFrontier(map, pose, t_s, &u)) {
          state_ = ExplorationState::kExploring;
          left_.clear();
          u.reason = "home, but a frontier given up for a while can be reached now; " + u.reason;
          u.state = state_;
          return u;
        }
      }
      if (left_.empty()) {
        state_ = ExplorationState::kCompleted;
        u.reason = Format("completed: home reached within %.3f m, no frontier left on the map", off, 0.0);
      } else {
        state_ = ExplorationState::kIncomplete;
        int cells = 0, unresolved = 0;
        std::string where;
        for (const FrontierLeft& f : left_) {
          cells += f.cells;
          unresolved += f.unresolved;
          if (where.size() < 200) where += Format(" (%.2f, %.2f)", f.x, f.y);
        }
        u.reason = Format("incomplete: home reached within %.3f m; %.0f frontier(s) left", off,
                          static_cast<double>(left_.size())) +
                   Format(" (%.0f cells; %.0f unresolved at their target", static_cast<double>(cells),
                          static_cast<double>(unresolved)) +
                   Format(", %.0f without a path) at", static_cast<double>(left_.size() - unresolved), 0.0) + where;
      }
    } else {  // SelectFrontier found nothing: path_ is still the way home
      if (path_.empty()) {
        plan_home("");
      } else if (!PathIsSafe(pose)) {
        plan_home("(path no longer safe, replanned)");
      } else if (std::hypot(pose.x - path_.back().x, pose.y - path_.back().y) <= options_.target_reached_m) {
        plan_home("(end of path reached outside the home tolerance)");
      }
    }
  }
  u.state = state_;
  if (state_ == ExplorationState::kFailed) u.reason = failure_reason_;
  return u;
}

}  // namespace mbot::planning
