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
#include "mbot/planning/benchmark_rules.hpp"
#include "mbot/reports/json.hpp"
#include "mbot/planning/obstacle_distance_grid.hpp"
#include "mbot/planning/planning_config.hpp"
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

struct MapReport {
  std::string name;
  int width = 0, height = 0;
  double resolution = 0.0;
  double distance_build_us = 0.0;
  double planner_setup_us = 0.0;
  std::vector<planning::CaseOutcome> cases;
  std::vector<double> success_us, failure_us;
  bool passed() const {
    for (const auto& c : cases) {
      if (!c.passed) return false;
    }
    return true;
  }
};

class AStarTestStage : public Stage {
 public:
  explicit AStarTestStage(AStarTestOptions o) : options_(std::move(o)), planner_(options_.astar) {}

  void OnEvent(const msgs::Event& ev) override {
    if (ev.kind == msgs::EventKind::kMap) {
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
    if (ev.kind != msgs::EventKind::kPlanRequest) return;
    if (!map_ || reports_.empty() || reports_.back().name != ev.channel) {
      throw std::runtime_error("astar_test: plan request on channel '" + ev.channel + "' before its map");
    }
    const auto& req = std::get<msgs::PlanRequest>(ev.payload);
    MapReport& r = reports_.back();
    planning::PlanResult result;
    for (int rep = 0; rep < options_.repeats; ++rep) {
      const auto t0 = Clock::now();
      result = planner_.Plan(req.start, req.goal);
      const double us = std::chrono::duration<double, std::micro>(Clock::now() - t0).count();
      (result.status == planning::PlanStatus::kFound ? r.success_us : r.failure_us).push_back(us);
    }
    r.cases.push_back(planning::JudgeBotlabCase(*map_, distances_, req.goal, req.expect_path == 1,
                                                options_.astar.robot_radius_m, result, req.index));
  }

  void Finish(const RunContext& ctx, bool interrupted) override {
    std::ostringstream table;
    char line[256];
    std::snprintf(line, sizeof line, "%-10s %-7s %6s  %-9s %6s %8s %8s %8s %8s %8s\n", "map", "result", "cases",
                  "attempts", "count", "min", "mean", "median", "max", "std");
    table << line;
    std::vector<std::string> failed_maps;
    reports::Json maps = reports::Json::array();
    for (const MapReport& r : reports_) {
      int passed = 0;
      for (const auto& c : r.cases) passed += c.passed;
      if (!r.passed()) failed_maps.push_back(r.name);
      const auto ok = reports::SampleStats::Of(r.success_us), bad = reports::SampleStats::Of(r.failure_us);
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
      reports::Json cases_json = reports::Json::array();
      for (const planning::CaseOutcome& c : r.cases) {
        cases_json.push_back({{"index", c.index},
                              {"expected", c.expected},
                              {"status", c.status},
                              {"found", c.found},
                              {"valid", c.valid},
                              {"passed", c.passed},
                              {"clearance_m", reports::Number(c.clearance_m)},
                              {"waypoints", c.waypoints},
                              {"length_m", reports::Number(c.length_m)},
                              {"expansions", c.expansions}});
      }
      maps.push_back({{"name", r.name},
                      {"passed", r.passed()},
                      {"size", {r.width, r.height}},
                      {"resolution_m", reports::Number(r.resolution)},
                      {"distance_build_us", reports::Number(r.distance_build_us)},
                      {"planner_setup_us", reports::Number(r.planner_setup_us)},
                      {"success_us", ok.ToJson()},
                      {"failure_us", bad.ToJson()},
                      {"cases", std::move(cases_json)}});
    }
    const reports::Json json = {{"repeats", options_.repeats},
                                {"robot_radius_m", reports::Number(options_.astar.robot_radius_m)},
                                {"interrupted", interrupted},
                                {"maps", std::move(maps)}};
    std::cout << "A* botlab cases, " << options_.repeats << " attempts each, planning call only, times in us\n"
              << table.str();
    const std::string path = ctx.output_dir + "/" + options_.json_file;
    reports::WriteJson(path, json);
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

static StageType AStarTestStageType() {
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

const RegisterStage kAStarTestRegistered{AStarTestStageType()};

}  // namespace mbot::app
