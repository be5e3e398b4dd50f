// `movingai_benchmark`: every scenario of a Moving AI `.map.scen` file on its map, with the
// benchmark's rules (octile moves, no corner cutting, zero clearance, no penalty). Writes one CSV
// row per scenario and prints a summary (optimal share, time per query, expansions per second).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <stdexcept>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/planning/astar.hpp"
#include "mbot/planning/benchmark_rules.hpp"
#include "mbot/planning/obstacle_distance_grid.hpp"
#include "mbot/planning/planning_config.hpp"
#include "mbot/reports/json.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

using Clock = std::chrono::steady_clock;

struct MovingAiBenchmarkOptions {
  std::string csv_file = "results.csv";
  std::string json_file = "summary.json";
  double tolerance = 0.01;      // |length - optimal| allowed
  bool require_optimal = true;  // fail the run when a scenario is not solved optimally
  int sample_every = 1;         // run scenarios whose index is a multiple of this (1: all)
  planning::SearchAlgorithm search = planning::SearchAlgorithm::kAuto;
  bool compare_astar = false;  // also run A* on every scenario: its times, its optimality, the speed-up
};

using Row = planning::ScenarioResult;

class MovingAiBenchmarkStage : public Stage {
 public:
  explicit MovingAiBenchmarkStage(MovingAiBenchmarkOptions o)
      : options_(std::move(o)),
        planner_(planning::MovingAiPlannerOptions(options_.search)),
        astar_(planning::MovingAiPlannerOptions(planning::SearchAlgorithm::kAStar)) {}

  void OnEvent(const msgs::Event& ev) override {
    if (ev.kind == msgs::EventKind::kMap) {
      map_name_ = ev.channel;
      const auto& grid = std::get<std::shared_ptr<const mapping::OccupancyGrid>>(ev.payload);
      if (grid->resolution() != 1.0)
        throw std::runtime_error("movingai_benchmark: map '" + ev.channel + "' is not a Moving AI map");
      const planning::ObstacleDistanceGrid distances(*grid, {});
      planner_.SetMap(distances);
      if (options_.compare_astar) astar_.SetMap(distances);
      return;
    }
    if (ev.kind != msgs::EventKind::kPlanRequest) return;
    if (map_name_ != ev.channel) throw std::runtime_error("movingai_benchmark: scenario before its map");
    const auto& req = std::get<msgs::PlanRequest>(ev.payload);
    if (req.index % options_.sample_every != 0) return;
    const auto t0 = Clock::now();
    const planning::PlanResult r = planner_.Plan(req.start, req.goal);
    Row row;
    row.time_us = std::chrono::duration<double, std::micro>(Clock::now() - t0).count();
    row.index = req.index;
    row.bucket = req.bucket;
    row.found = r.status == planning::PlanStatus::kFound;
    row.length = r.length_m;  // 1 m cells: metres = cells
    row.optimal = req.optimal_length_m;
    row.expansions = r.expansions;
    if (options_.compare_astar) {
      const auto t1 = Clock::now();
      const planning::PlanResult a = astar_.Plan(req.start, req.goal);
      row.astar_time_us = std::chrono::duration<double, std::micro>(Clock::now() - t1).count();
      row.astar_found = a.status == planning::PlanStatus::kFound;
      row.astar_length = a.length_m;
    }
    rows_.push_back(row);
  }

  void Finish(const RunContext& ctx, bool interrupted) override {
    const bool compare = options_.compare_astar;
    std::vector<double> times, astar_times;
    int optimal = 0, found = 0, astar_optimal = 0;
    int64_t expansions = 0;
    double total_us = 0.0;
    std::vector<const Row*> wrong;
    auto is_optimal = [&](bool ok, double length, double best) {
      return planning::SolvedOptimally(ok, length, best, options_.tolerance);
    };
    for (const Row& r : rows_) {
      times.push_back(r.time_us);
      total_us += r.time_us;
      expansions += r.expansions;
      found += r.found;
      const bool ours = is_optimal(r.found, r.length, r.optimal);
      const bool astar = !compare || is_optimal(r.astar_found, r.astar_length, r.optimal);
      optimal += ours;
      if (compare) {
        astar_times.push_back(r.astar_time_us);
        astar_optimal += astar;
      }
      if (!ours || !astar) wrong.push_back(&r);
    }
    const std::string csv = ctx.output_dir + "/" + options_.csv_file;
    WriteFileAtomically(csv, [&](std::ostream& out) {
      out << "index,bucket,found,length,optimal,expansions,time_us" << (compare ? ",astar_length,astar_time_us" : "")
          << "\n";
      char line[200];
      for (const Row& r : rows_) {
        std::snprintf(line, sizeof line, "%d,%d,%d,%.6f,%.6f,%lld,%.3f", r.index, r.bucket, r.found ? 1 : 0, r.length,
                      r.optimal, static_cast<long long>(r.expansions), r.time_us);
        out << line;
        if (compare) {
          std::snprintf(line, sizeof line, ",%.6f,%.3f", r.astar_found ? r.astar_length : -1.0, r.astar_time_us);
          out << line;
        }
        out << "\n";
      }
    });
    const reports::SampleStats t = reports::SampleStats::Of(times);
    const double rate = total_us > 0 ? expansions / (total_us * 1e-6) : 0.0;
    const char* search = planner_.UsesJumpPoints() ? "jps" : "astar";
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "%s (%s): %zu problems, %d found, %d optimal within %.2g; time per query mean %.1f us, median %.1f "
                  "us, max %.1f us; %.2f M expansions/s\n",
                  map_name_.c_str(), search, rows_.size(), found, optimal, options_.tolerance, t.mean, t.median, t.max,
                  rate * 1e-6);
    std::cout << buf;
    const reports::SampleStats a = reports::SampleStats::Of(astar_times);
    if (compare) {
      std::snprintf(buf, sizeof buf,
                    "  A* on the same queries: %d optimal; mean %.1f us, median %.1f us; speed-up of the mean %.2fx\n",
                    astar_optimal, a.mean, a.median, t.mean > 0 ? a.mean / t.mean : 0.0);
      std::cout << buf;
    }
    for (size_t i = 0; i < wrong.size() && i < 10; ++i) {
      std::printf("  scenario %d: found %d, length %.4f, optimal %.4f%s\n", wrong[i]->index, wrong[i]->found,
                  wrong[i]->length, wrong[i]->optimal,
                  compare ? (" (A* " + std::to_string(wrong[i]->astar_length) + ")").c_str() : "");
    }
    reports::Json j = {
        {"map", map_name_},      {"search", search},         {"problems", rows_.size()},
        {"found", found},        {"optimal", optimal},       {"tolerance", reports::Number(options_.tolerance)},
        {"time_us", t.ToJson()}, {"expansions", expansions}, {"expansions_per_s", reports::Number(rate)}};
    if (compare) {
      j["astar"] = {{"optimal", astar_optimal},
                    {"time_us", a.ToJson()},
                    {"speedup_of_mean", reports::Number(t.mean > 0 ? a.mean / t.mean : 0.0)}};
    }
    j["interrupted"] = interrupted;
    reports::WriteJson(ctx.output_dir + "/" + options_.json_file, j);
    mbot::log::Info("wrote " + csv);
    if (options_.require_optimal && !wrong.empty() && !interrupted) {
      throw std::runtime_error("movingai_benchmark: " + std::to_string(wrong.size()) + " of " +
                               std::to_string(rows_.size()) + " scenarios not solved optimally");
    }
  }

 private:
  MovingAiBenchmarkOptions options_;
  planning::AStarPlanner planner_, astar_;
  std::string map_name_;
  std::vector<Row> rows_;
};

}  // namespace

static StageType MovingAiBenchmarkStageType() {
  return {"movingai_benchmark",
          "runs the scenarios of a Moving AI .map.scen file (all, or every sample_every-th) (octile, no corner "
          "cutting) and checks optimal lengths",
          [](config::Section& s) -> std::unique_ptr<Stage> {
            MovingAiBenchmarkOptions o;
            o.csv_file = s.GetString("csv_file", o.csv_file, "per-scenario results in output.dir");
            o.json_file = s.GetString("json_file", o.json_file, "summary in output.dir");
            o.tolerance = s.GetDouble("tolerance", o.tolerance, "allowed |length - optimal|", 0.0, 1e6);
            o.require_optimal = s.GetBool("require_optimal", o.require_optimal,
                                          "fail the run when any scenario is not solved optimally");
            o.sample_every =
                static_cast<int>(s.GetInt("sample_every", o.sample_every,
                                          "run only scenarios whose index is a multiple of this (1: every one; "
                                          "the default ctest run samples, the movingai_full label runs all)",
                                          1, 1000000));
            o.search = planning::ParseSearchAlgorithm(s, o.search);
            o.compare_astar = s.GetBool("compare_astar", o.compare_astar,
                                        "also run A* on every scenario: its optimality, times and the speed-up");
            return std::make_unique<MovingAiBenchmarkStage>(o);
          }};
}

const RegisterStage kMovingAiBenchmarkRegistered{MovingAiBenchmarkStageType()};

}  // namespace mbot::app
