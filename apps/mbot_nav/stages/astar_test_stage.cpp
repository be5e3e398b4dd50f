// `astar_test`: the botlab A* regression with the original pass rules. For every map of the input
// (a `*_poses.txt` file or folder of them) it builds the obstacle distance grid, runs each case
// `repeats` times timing only the planning call, judges it as the botlab astar_test did, and prints
// per map PASSED/FAILED and the timing table of the reports (min, mean, median, max, std in µs,
// successful and failed attempts apart). Any failed map makes the run fail after the report is written.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <stdexcept>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/planning/astar.hpp"
#include "mbot/planning/obstacle_distance_grid.hpp"
#include "mbot/planning/planning_config.hpp"
#include "report.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

using Clock = std::chrono::steady_clock;

struct AStarTestOptions {
  planning::AStarOptions astar;
  planning::ObstacleDistanceOptions distance;
  int repeats = 10;
  std::string json_file = "astar_test.json";
};

struct CaseOutcome {
  int index = 0;
  bool expected = false;
  bool found = false;
  bool valid = false;
  bool passed = false;
  std::string status;
  double clearance_m = 0.0;
  size_t waypoints = 0;
  double length_m = 0.0;
  int64_t expansions = 0;
};

struct MapReport {
  std::string name;
  int width = 0, height = 0;
  double resolution = 0.0;
  double distance_build_us = 0.0;
  double planner_setup_us = 0.0;
  std::vector<CaseOutcome> cases;
  std::vector<double> success_us, failure_us;
  bool passed() const {
    for (const auto& c : cases) {
      if (!c.passed) return false;
    }
    return true;
  }
};

// The botlab rule, checked on the occupancy grid itself (not on the planner's distance grid): a
// waypoint is invalid when a cell with log-odds > 0 lies within the robot radius of its cell.
bool WaypointIsSafe(const mapping::OccupancyGrid& map, double x, double y, double radius) {
  int cx, cy;
  map.WorldToCell(x, y, &cx, &cy);
  const int r = static_cast<int>(std::ceil(radius / map.resolution()));
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      const int nx = cx + dx, ny = cy + dy;
      if (!map.IsInside(nx, ny)) continue;
      if (std::hypot(dx, dy) * map.resolution() <= radius && map.at(nx, ny) > 0) return false;
    }
  }
  return true;
}

class AStarTestStage : public Stage {
 public:
  explicit AStarTestStage(AStarTestOptions o) : options_(std::move(o)), planner_(options_.astar) {}

  void OnEvent(const drivers::Event& ev) override {
    if (ev.kind == drivers::EventKind::kMap) {
      map_ = std::get<std::shared_ptr<const mapping::OccupancyGrid>>(ev.payload);
      reports_.push_back(MapReport{});
      MapReport& r = reports_.back();
      r.name = ev.channel;
      r.width = map_->width();
      r.height = map_->height();
      r.resolution = map_->resolution();
      auto t0 = Clock::now();
      distances_ = planning::ObstacleDistanceGrid(*map_, options_.distance);
      auto t1 = Clock::now();
      planner_.SetMap(distances_);
      auto t2 = Clock::now();
      r.distance_build_us = std::chrono::duration<double, std::micro>(t1 - t0).count();
      r.planner_setup_us = std::chrono::duration<double, std::micro>(t2 - t1).count();
      return;
    }
    if (ev.kind != drivers::EventKind::kPlanRequest) return;
    if (!map_ || reports_.empty() || reports_.back().name != ev.channel) {
      throw std::runtime_error("astar_test: plan request on channel '" + ev.channel + "' before its map");
    }
    const auto& req = std::get<drivers::PlanRequest>(ev.payload);
    MapReport& r = reports_.back();
    const double radius = options_.astar.robot_radius_m;
    // Goal validity as the botlab test checks it: the goal cell's obstacle distance exceeds the radius.
    int gx, gy;
    map_->WorldToCell(req.goal.x, req.goal.y, &gx, &gy);
    const bool goal_valid = distances_.IsInside(gx, gy) && distances_.at(gx, gy) > radius;
    planning::PlanResult result;
    for (int rep = 0; rep < options_.repeats; ++rep) {
      const auto t0 = Clock::now();
      result = planner_.Plan(req.start, req.goal);
      const double us = std::chrono::duration<double, std::micro>(Clock::now() - t0).count();
      (result.status == planning::PlanStatus::kFound ? r.success_us : r.failure_us).push_back(us);
    }
    CaseOutcome c;
    c.index = req.index;
    c.expected = req.expect_path == 1;
    c.status = planning::ToString(result.status);
    c.clearance_m = result.clearance_m;
    c.waypoints = result.path.size();
    c.length_m = result.length_m;
    c.expansions = result.expansions;
    if (goal_valid && result.path.size() > 1) {
      int lx, ly;
      map_->WorldToCell(result.path.back().x, result.path.back().y, &lx, &ly);
      c.found = lx == gx && ly == gy;
    }
    c.valid = true;
    for (const auto& p : result.path) c.valid = c.valid && WaypointIsSafe(*map_, p.x, p.y, radius);
    c.passed = c.expected ? (c.found && c.valid) : !c.found;
    r.cases.push_back(c);
  }

  void Finish(const RunContext& ctx, bool interrupted) override {
    std::ostringstream table;
    char line[256];
    std::snprintf(line, sizeof line, "%-10s %-7s %6s  %-9s %6s %8s %8s %8s %8s %8s\n", "map", "result", "cases",
                  "attempts", "count", "min", "mean", "median", "max", "std");
    table << line;
    std::vector<std::string> failed_maps;
    std::ostringstream json;
    json << "{\n  \"repeats\": " << options_.repeats
         << ",\n  \"robot_radius_m\": " << Num(options_.astar.robot_radius_m)
         << ",\n  \"interrupted\": " << (interrupted ? "true" : "false") << ",\n  \"maps\": [";
    for (size_t i = 0; i < reports_.size(); ++i) {
      const MapReport& r = reports_[i];
      int passed = 0;
      for (const auto& c : r.cases) passed += c.passed;
      if (!r.passed()) failed_maps.push_back(r.name);
      const SampleStats ok = SampleStats::Of(r.success_us), bad = SampleStats::Of(r.failure_us);
      const std::string cases = std::to_string(passed) + "/" + std::to_string(r.cases.size());
      std::snprintf(line, sizeof line, "%-10s %-7s %6s  %-9s %6zu %8.1f %8.1f %8.1f %8.1f %8.1f\n", r.name.c_str(),
                    r.passed() ? "PASSED" : "FAILED", cases.c_str(), "success", ok.count, ok.min, ok.mean, ok.median,
                    ok.max, ok.std);
      table << line;
      std::snprintf(line, sizeof line, "%-10s %-7s %6s  %-9s %6zu %8.1f %8.1f %8.1f %8.1f %8.1f\n", "", "", "",
                    "failed", bad.count, bad.min, bad.mean, bad.median, bad.max, bad.std);
      table << line;
      for (const auto& c : r.cases) {
        if (c.passed) continue;
        std::snprintf(line, sizeof line, "  %s case %d FAILED: expected %s, planner said '%s' (found %d, valid %d)\n",
                      r.name.c_str(), c.index, c.expected ? "a path" : "no path", c.status.c_str(), c.found, c.valid);
        table << line;
      }
      json << (i ? "," : "") << "\n    {\"name\": " << JsonString(r.name)
           << ", \"passed\": " << (r.passed() ? "true" : "false") << ", \"size\": [" << r.width << ", " << r.height
           << "], \"resolution_m\": " << Num(r.resolution) << ", \"distance_build_us\": " << Num(r.distance_build_us)
           << ", \"planner_setup_us\": " << Num(r.planner_setup_us) << ",\n     \"success_us\": " << ok.Json()
           << ",\n     \"failure_us\": " << bad.Json() << ",\n     \"cases\": [";
      for (size_t k = 0; k < r.cases.size(); ++k) {
        const auto& c = r.cases[k];
        json << (k ? ", " : "") << "{\"index\": " << c.index << ", \"expected\": " << (c.expected ? "true" : "false")
             << ", \"status\": " << JsonString(c.status) << ", \"found\": " << (c.found ? "true" : "false")
             << ", \"valid\": " << (c.valid ? "true" : "false") << ", \"passed\": " << (c.passed ? "true" : "false")
             << ", \"clearance_m\": " << Num(c.clearance_m) << ", \"waypoints\": " << c.waypoints
             << ", \"length_m\": " << Num(c.length_m) << ", \"expansions\": " << c.expansions << "}";
      }
      json << "]}";
    }
    json << "\n  ]\n}\n";
    std::cout << "A* botlab cases, " << options_.repeats << " attempts each, planning call only, times in us\n"
              << table.str();
    const std::string path = ctx.output_dir + "/" + options_.json_file;
    WriteFileAtomically(path, [&](std::ostream& out) { out << json.str(); });
    mbot::log::Info("wrote " + path);
    if (reports_.empty()) throw std::runtime_error("astar_test: the input held no map and no case");
    if (!failed_maps.empty() && !interrupted) {
      std::string names;
      for (const auto& n : failed_maps) names += (names.empty() ? "" : ", ") + n;
      throw std::runtime_error("astar_test: " + std::to_string(failed_maps.size()) + " of " +
                               std::to_string(reports_.size()) + " maps FAILED: " + names);
    }
  }

 private:
  AStarTestOptions options_;
  planning::AStarPlanner planner_;
  std::shared_ptr<const mapping::OccupancyGrid> map_;
  planning::ObstacleDistanceGrid distances_;
  std::vector<MapReport> reports_;
};

}  // namespace

StageType AStarTestStageType() {
  return {"astar_test",
          "the botlab A* regression: runs *_poses.txt cases on their maps with the original pass rules, prints "
          "PASSED/FAILED per map and planning-time statistics",
          [](config::Section& s) -> std::unique_ptr<Stage> {
            AStarTestOptions o;
            o.repeats =
                static_cast<int>(s.GetInt("repeats", o.repeats, "planning calls per case (timed each)", 1, 100000));
            o.json_file = s.GetString("json_file", o.json_file, "report file in output.dir");
            o.astar = planning::ParseAStarOptions(s);
            o.distance = planning::ParseObstacleDistanceOptions(s);
            return std::make_unique<AStarTestStage>(o);
          }};
}

}  // namespace mbot::app
