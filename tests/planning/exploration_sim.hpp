// A scripted robot for exploration tests: it reveals a true map around itself (rays that stop at
// walls), follows the explorer's paths exactly, and records what it did. No simulator needed.
#pragma once

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "mbot/planning/exploration.hpp"

namespace mbot::planning::testing {

struct ScriptedRun {
  ExplorationState final_state = ExplorationState::kInitializing;
  std::string reason;
  motion::Pose2D final_pose;
  double driven_m = 0.0;
  double min_true_clearance_m = 1e9;  // smallest true obstacle distance along the driven path
  int updates = 0;
  int paths = 0;
  double coverage = 0.0;  // share of true free cells reachable from home now known
  mapping::OccupancyGrid known;
  std::vector<FrontierLeft> left;  // the explorer's account of the frontiers left at the end
};

// Marks what a 360° sensor of `range_m` sees from (x, y): free cells along each ray up to the first
// occupied cell (marked occupied). Cells unknown in the truth stop the ray and stay unknown.
inline void Reveal(const mapping::OccupancyGrid& truth, double x, double y, double range_m,
                   mapping::OccupancyGrid* known) {
  const double res = truth.resolution();
  const int rays = static_cast<int>(std::ceil(2 * M_PI * range_m / res));
  for (int i = 0; i < rays; ++i) {
    const double a = 2 * M_PI * i / rays;
    const double dx = std::cos(a), dy = std::sin(a);
    int last_x = -1, last_y = -1;
    for (double s = 0; s <= range_m; s += res * 0.5) {
      int cx, cy;
      truth.WorldToCell(x + s * dx, y + s * dy, &cx, &cy);
      if (!truth.IsInside(cx, cy)) break;
      if (cx == last_x && cy == last_y) continue;
      last_x = cx;
      last_y = cy;
      const int8_t t = truth.at(cx, cy);
      if (t > 0) {
        known->at(cx, cy) = 100;
        break;
      }
      if (t == 0) break;
      known->at(cx, cy) = -100;
    }
  }
}

// Free cells of `truth` the robot could stand on (obstacle distance > radius, unknown blocking)
// and reach from `home`.
inline std::vector<int> ReachableCells(const mapping::OccupancyGrid& truth, const motion::Pose2D& home, double radius) {
  ObstacleDistanceGrid d(truth, {true, 0});
  std::vector<int> out;
  std::vector<uint8_t> seen(truth.cells().size(), 0);
  int hx, hy;
  truth.WorldToCell(home.x, home.y, &hx, &hy);
  const int w = truth.width();
  std::vector<int> q = {hy * w + hx};
  seen[q[0]] = 1;
  for (size_t i = 0; i < q.size(); ++i) {
    const int c = q[i];
    out.push_back(c);
    const int x = c % w, y = c / w;
    const int nx[4] = {x + 1, x - 1, x, x}, ny[4] = {y, y, y + 1, y - 1};
    for (int k = 0; k < 4; ++k) {
      if (!truth.IsInside(nx[k], ny[k])) continue;
      const int n = ny[k] * w + nx[k];
      if (!seen[n] && d.at(nx[k], ny[k]) > radius) {
        seen[n] = 1;
        q.push_back(n);
      }
    }
  }
  return out;
}

// Drives the explorer to the end (or `max_updates`). `on_update` may change the truth mid-run.
inline ScriptedRun RunScripted(mapping::OccupancyGrid truth, const motion::Pose2D& home,
                               const ExplorationOptions& options, double sensor_range_m, int max_updates = 5000,
                               const std::function<void(int, const motion::Pose2D&, mapping::OccupancyGrid*,
                                                        mapping::OccupancyGrid*)>& on_update = nullptr) {
  ScriptedRun run;
  Explorer explorer(options);
  mapping::OccupancyGrid known(truth.width(), truth.height(), truth.resolution(), truth.origin_x(), truth.origin_y(),
                               0);
  ObstacleDistanceGrid true_distance(truth, {true, 0});
  motion::Pose2D pose = home;
  std::vector<motion::Pose2D> path;
  size_t next = 1;
  const double step = 0.05, update_every = 0.25;
  double since_update = update_every, t = 0.0;
  Reveal(truth, pose.x, pose.y, sensor_range_m, &known);
  for (; run.updates < max_updates;) {
    if (since_update >= update_every || next >= path.size()) {
      if (on_update) {
        on_update(run.updates, pose, &truth, &known);
        true_distance = ObstacleDistanceGrid(truth, {true, 0});
      }
      const ExplorationUpdate u = explorer.Update(known, pose, t);
      ++run.updates;
      since_update = 0.0;
      if (u.new_path) {
        path = u.path;
        next = 1;
        ++run.paths;
      }
      if (u.state == ExplorationState::kCompleted || u.state == ExplorationState::kIncomplete ||
          u.state == ExplorationState::kFailed) {
        run.final_state = u.state;
        run.reason = u.reason;
        break;
      }
      if (next >= path.size()) {
        t += 1.0;  // stopped: time passes, nothing moves
        continue;
      }
    }
    // Move `step` along the path (through waypoints).
    double left = step;
    while (left > 1e-12 && next < path.size()) {
      const double dx = path[next].x - pose.x, dy = path[next].y - pose.y, d = std::hypot(dx, dy);
      if (d <= left) {
        pose.x = path[next].x;
        pose.y = path[next].y;
        left -= d;
        run.driven_m += d;
        ++next;
      } else {
        pose.x += dx / d * left;
        pose.y += dy / d * left;
        run.driven_m += left;
        left = 0;
      }
      pose.theta = std::atan2(dy, dx);
      int cx, cy;
      truth.WorldToCell(pose.x, pose.y, &cx, &cy);
      run.min_true_clearance_m = std::min<double>(run.min_true_clearance_m, true_distance.at(cx, cy));
    }
    t += step / 0.25;  // 0.25 m/s
    since_update += step;
    Reveal(truth, pose.x, pose.y, sensor_range_m, &known);
  }
  run.final_pose = pose;
  const std::vector<int> reachable = ReachableCells(truth, home, options.astar.robot_radius_m);
  int seen = 0;
  for (int c : reachable) seen += known.cells()[c] != 0;
  run.coverage = reachable.empty() ? 0.0 : double(seen) / reachable.size();
  run.known = std::move(known);
  run.left = explorer.left();
  if (run.final_state == ExplorationState::kInitializing) {
    run.final_state = explorer.state();
    run.reason = "stopped after " + std::to_string(run.updates) + " updates in state " + ToString(explorer.state());
  }
  return run;
}

}  // namespace mbot::planning::testing
