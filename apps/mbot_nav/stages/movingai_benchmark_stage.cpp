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
#include "mbot/planning/obstacle_distance_grid.hpp"
#include "report.hpp"
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
};

struct Row {
  int index = 0, bucket = 0;
  bool found = false;
  double length = 0.0, optimal = 0.0, time_us = 0.0;
  int64_t expansions = 0;
};

class MovingAiBenchmarkStage : public Stage {
 public:
  explicit MovingAiBenchmarkStage(MovingAiBenchmarkOptions o) : options_(std::move(o)), planner_(PlannerOptions()) {}

  static planning::AStarOptions PlannerOptions() {
    planning::AStarOptions a;
    a.robot_radius_m = 0.0;
    a.ease_start_m = 0.0;
    a.ease_max_m = 0.0;
    a.penalty_weight = 0.0;
    a.prune = planning::PruneMode::kNone;
    return a;
  }

  void OnEvent(const drivers::Event& ev) override {
    if (ev.kind == drivers::EventKind::kMap) {
      map_name_ = ev.channel;
      const auto& grid = std::get<std::shared_ptr<const mapping::OccupancyGrid>>(ev.payload);
      if (grid->resolution() != 1.0)
        throw std::runtime_error("movingai_benchmark: map '" + ev.channel + "' is not a Moving AI map");
      planner_.SetMap(planning::ObstacleDistanceGrid(*grid, {}));
      return;
    }
    if (ev.kind != drivers::EventKind::kPlanRequest) return;
    if (map_name_ != ev.channel) throw std::runtime_error("movingai_benchmark: scenario before its map");
    const auto& req = std::get<drivers::PlanRequest>(ev.payload);
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
    rows_.push_back(row);
  }

  void Finish(const RunContext& ctx, bool interrupted) override {
    std::vector<double> times;
    int optimal = 0, found = 0;
    int64_t expansions = 0;
    double total_us = 0.0;
    std::vector<const Row*> wrong;
    for (const Row& r : rows_) {
      times.push_back(r.time_us);
      total_us += r.time_us;
      expansions += r.expansions;
      found += r.found;
      if (r.found && std::abs(r.length - r.optimal) <= options_.tolerance)
        ++optimal;
      else
        wrong.push_back(&r);
    }
    const std::string csv = ctx.output_dir + "/" + options_.csv_file;
    WriteFileAtomically(csv, [&](std::ostream& out) {
      out << "index,bucket,found,length,optimal,expansions,time_us\n";
      char line[160];
      for (const Row& r : rows_) {
        std::snprintf(line, sizeof line, "%d,%d,%d,%.6f,%.6f,%lld,%.3f\n", r.index, r.bucket, r.found ? 1 : 0, r.length,
                      r.optimal, static_cast<long long>(r.expansions), r.time_us);
        out << line;
      }
    });
    const SampleStats t = SampleStats::Of(times);
    const double rate = total_us > 0 ? expansions / (total_us * 1e-6) : 0.0;
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "%s: %zu problems, %d found, %d optimal within %.2g; time per query mean %.1f us, median %.1f us, "
                  "max %.1f us; %.2f M expansions/s\n",
                  map_name_.c_str(), rows_.size(), found, optimal, options_.tolerance, t.mean, t.median, t.max,
                  rate * 1e-6);
    std::cout << buf;
    for (size_t i = 0; i < wrong.size() && i < 10; ++i) {
      std::printf("  scenario %d: found %d, length %.4f, optimal %.4f\n", wrong[i]->index, wrong[i]->found,
                  wrong[i]->length, wrong[i]->optimal);
    }
    WriteFileAtomically(ctx.output_dir + "/" + options_.json_file, [&](std::ostream& out) {
      out << "{\"map\": " << JsonString(map_name_) << ", \"problems\": " << rows_.size() << ", \"found\": " << found
          << ", \"optimal\": " << optimal << ", \"tolerance\": " << Num(options_.tolerance)
          << ", \"time_us\": " << t.Json() << ", \"expansions\": " << expansions
          << ", \"expansions_per_s\": " << Num(rate) << ", \"interrupted\": " << (interrupted ? "true" : "false")
          << "}\n";
    });
    mbot::log::Info("wrote " + csv);
    if (options_.require_optimal && !wrong.empty() && !interrupted) {
      throw std::runtime_error("movingai_benchmark: " + std::to_string(wrong.size()) + " of " +
                               std::to_string(rows_.size()) + " scenarios not solved optimally");
    }
  }

 private:
  MovingAiBenchmarkOptions options_;
  planning::AStarPlanner planner_;
  std::string map_name_;
  std::vector<Row> rows_;
};

}  // namespace

StageType MovingAiBenchmarkStageType() {
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
            return std::make_unique<MovingAiBenchmarkStage>(o);
          }};
}

}  // namespace mbot::app
