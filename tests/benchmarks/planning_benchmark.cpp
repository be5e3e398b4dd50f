// Planning benchmarks (Google Benchmark), each beside a baseline measured in the same run:
//  - obstacle distance grid: ours (exact EDT) vs OpenCV's cv::distanceTransform (DIST_L2, precise)
//    and vs a classic 8-connected brushfire (what the botlab reports built), on a real 800×800 arena
//    map and the 2000×2000 100by100_20 world;
//  - A* per botlab case file: ours vs a textbook A* (std::priority_queue, per-query allocation,
//    no easing), both timing only the planning call, like the reports.
// Run: build/tests/mbot_planning_benchmark [--benchmark_repetitions=5 --benchmark_report_aggregates_only=true]
#include <benchmark/benchmark.h>

#include <cmath>
#include <fstream>
#include <opencv2/imgproc.hpp>
#include <queue>

#include "mbot/common/config.hpp"
#include "mbot/drivers/map_io.hpp"
#include "mbot/planning/astar.hpp"
#include "mbot/planning/obstacle_distance_grid.hpp"

namespace {

using mbot::mapping::OccupancyGrid;
using mbot::motion::Pose2D;
namespace planning = mbot::planning;

std::string Data(const std::string& rel) { return mbot::config::DatasetsDir() + "/" + rel; }

const OccupancyGrid& Map(const std::string& rel) {
  static std::map<std::string, OccupancyGrid> cache;
  auto it = cache.find(rel);
  if (it == cache.end()) it = cache.emplace(rel, mbot::drivers::ReadAnyMap(Data(rel))).first;
  return it->second;
}

const char* kDistanceMaps[] = {"botlab/mbot_example_logs_maps/drive_square.map", "worlds/100by100_20.yaml"};

void BM_DistanceGrid_Ours(benchmark::State& state) {
  const OccupancyGrid& g = Map(kDistanceMaps[state.range(0)]);
  planning::ObstacleDistanceGrid d(g, {});  // buffers kept, as OpenCV's output Mat is below
  for (auto _ : state) {
    d.Recompute(g);
    benchmark::DoNotOptimize(d.distances().data());
  }
  state.SetLabel(std::to_string(g.width()) + "x" + std::to_string(g.height()));
}

void BM_DistanceGrid_OpenCV(benchmark::State& state) {
  const OccupancyGrid& g = Map(kDistanceMaps[state.range(0)]);
  // OpenCV measures the distance to the nearest zero pixel: obstacles are 0, free space 255.
  cv::Mat src(g.height(), g.width(), CV_8UC1);
  for (int y = 0; y < g.height(); ++y) {
    for (int x = 0; x < g.width(); ++x) src.at<uint8_t>(y, x) = g.at(x, y) > 0 ? 0 : 255;
  }
  cv::Mat dist;
  for (auto _ : state) {
    cv::distanceTransform(src, dist, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
    dist *= g.resolution();
    benchmark::DoNotOptimize(dist.data);
  }
  state.SetLabel(std::to_string(g.width()) + "x" + std::to_string(g.height()));
}

// One map update as an explorer sees it: a disk of radius `range(1)` cells that was unknown is now
// seen (free, with its walls), then unseen again, alternately. Incremental: the distance grid's
// Update plus the planner's UpdateMap; rebuild: a fresh transform plus SetMap. Exploration's
// options (unknown cells are obstacles), the real 800×800 arena map.
struct MapPair {
  OccupancyGrid seen, unseen;
};
const MapPair& UpdatePair(int radius) {
  static std::map<int, MapPair> cache;
  auto it = cache.find(radius);
  if (it != cache.end()) return it->second;
  const OccupancyGrid& g = Map(kDistanceMaps[0]);
  MapPair p{g, g};
  const int cx = g.width() / 2, cy = g.height() / 2;
  for (int y = cy - radius; y <= cy + radius; ++y)
    for (int x = cx - radius; x <= cx + radius; ++x)
      if ((x - cx) * (x - cx) + (y - cy) * (y - cy) <= radius * radius) p.unseen.at(x, y) = 0;
  return cache.emplace(radius, std::move(p)).first->second;
}
const planning::ObstacleDistanceOptions kExploreDistance{true, 0, 0.0, -1};

void BM_MapUpdate_Incremental(benchmark::State& state) {
  const MapPair& p = UpdatePair(static_cast<int>(state.range(0)));
  planning::ObstacleDistanceGrid d(p.seen, kExploreDistance);
  planning::AStarPlanner planner;
  planner.SetMap(d);
  bool seen = false;
  int64_t changed_cells = 0;
  for (auto _ : state) {
    const mbot::mapping::CellRect r = d.Update(seen ? p.seen : p.unseen);
    planner.UpdateMap(d, r);
    changed_cells += r.empty() ? 0 : int64_t{r.x1 - r.x0 + 1} * (r.y1 - r.y0 + 1);
    seen = !seen;
  }
  state.SetLabel("800x800, a disk of radius " + std::to_string(state.range(0)) + " cells changes; " +
                 std::to_string(changed_cells / std::max<int64_t>(1, state.iterations())) + " cells redone");
}

void BM_MapUpdate_Rebuild(benchmark::State& state) {
  const MapPair& p = UpdatePair(static_cast<int>(state.range(0)));
  planning::AStarPlanner planner;
  bool seen = false;
  for (auto _ : state) {
    planner.SetMap(planning::ObstacleDistanceGrid(seen ? p.seen : p.unseen, kExploreDistance));
    seen = !seen;
  }
  state.SetLabel("800x800, a disk of radius " + std::to_string(state.range(0)) + " cells changes");
}

BENCHMARK(BM_MapUpdate_Incremental)->Arg(20)->Arg(60)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MapUpdate_Rebuild)->Arg(20)->Arg(60)->Unit(benchmark::kMillisecond);

// The reports' brushfire: BFS from obstacle cells over 8 neighbours, distance = parent's + step.
// Not exact (it over-estimates off the 8 directions); the timing baseline only.
void BM_DistanceGrid_Brushfire(benchmark::State& state) {
  const OccupancyGrid& g = Map(kDistanceMaps[state.range(0)]);
  const int w = g.width(), h = g.height();
  for (auto _ : state) {
    std::vector<float> d(g.cells().size(), -1.0f);
    std::queue<int> q;
    for (int i = 0; i < static_cast<int>(d.size()); ++i) {
      if (g.cells()[i] > 0) {
        d[i] = 0.0f;
        q.push(i);
      }
    }
    while (!q.empty()) {
      const int c = q.front();
      q.pop();
      const int cx = c % w, cy = c / w;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = cx + dx, ny = cy + dy;
          if ((dx | dy) == 0 || nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
          const int n = ny * w + nx;
          const float nd = d[c] + static_cast<float>((dx && dy ? M_SQRT2 : 1.0) * g.resolution());
          if (d[n] < 0.0f || nd < d[n]) {
            d[n] = nd;
            q.push(n);
          }
        }
      }
    }
    benchmark::DoNotOptimize(d.data());
  }
  state.SetLabel(std::to_string(w) + "x" + std::to_string(h));
}

BENCHMARK(BM_DistanceGrid_Ours)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DistanceGrid_OpenCV)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DistanceGrid_Brushfire)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

struct Case {
  Pose2D start, goal;
};

std::vector<Case> ReadCases(const std::string& name) {
  std::ifstream in(Data("botlab/astar/" + name + "_poses.txt"));
  int n = 0;
  in >> n;
  std::vector<Case> out(n);
  int should;
  for (auto& c : out) in >> c.start.x >> c.start.y >> c.goal.x >> c.goal.y >> should;
  return out;
}

const char* kAStarMaps[] = {"convex", "empty", "maze", "narrow", "wide"};

void BM_AStar_Ours(benchmark::State& state) {
  const std::string name = kAStarMaps[state.range(0)];
  const OccupancyGrid& g = Map("botlab/astar/" + name + ".map");
  planning::AStarPlanner planner;
  planner.SetMap(planning::ObstacleDistanceGrid(g, {}));
  const std::vector<Case> cases = ReadCases(name);
  for (const Case& c : cases) planner.Plan(c.start, c.goal);  // connectivity labels built once, untimed
  size_t i = 0;
  for (auto _ : state) {
    const Case& c = cases[i++ % cases.size()];
    benchmark::DoNotOptimize(planner.Plan(c.start, c.goal).status);
  }
  state.SetLabel(name + " (per query, cases in turn)");
}

// A textbook grid A*: priority_queue of (f, cell), closed set and g freshly allocated per query,
// same moves, costs and clearance rule (radius only), no easing, no connectivity shortcut.
int TextbookAStar(const planning::ObstacleDistanceGrid& d, const Pose2D& s, const Pose2D& t, double clearance) {
  const int w = d.width(), h = d.height();
  int sx, sy, gx, gy;
  d.WorldToCell(s.x, s.y, &sx, &sy);
  d.WorldToCell(t.x, t.y, &gx, &gy);
  if (!d.IsInside(sx, sy) || !d.IsInside(gx, gy) || d.at(gx, gy) <= clearance) return 0;
  std::vector<double> g(static_cast<size_t>(w) * h, INFINITY);
  std::vector<uint8_t> closed(g.size(), 0);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> open;
  auto heuristic = [&](int x, int y) {
    const int dx = std::abs(x - gx), dy = std::abs(y - gy);
    return std::max(dx, dy) + (M_SQRT2 - 1) * std::min(dx, dy);
  };
  g[sy * w + sx] = 0;
  open.push({heuristic(sx, sy), sy * w + sx});
  while (!open.empty()) {
    const int c = open.top().second;
    open.pop();
    if (closed[c]) continue;
    closed[c] = 1;
    const int cx = c % w, cy = c / w;
    if (cx == gx && cy == gy) return 1;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int nx = cx + dx, ny = cy + dy;
        if ((dx | dy) == 0 || !d.IsInside(nx, ny) || d.at(nx, ny) <= clearance) continue;
        if (dx && dy && (d.at(cx + dx, cy) <= clearance || d.at(cx, cy + dy) <= clearance)) continue;
        const int n = ny * w + nx;
        const double ng = g[c] + (dx && dy ? M_SQRT2 : 1.0);
        if (ng < g[n]) {
          g[n] = ng;
          open.push({ng + heuristic(nx, ny), n});
        }
      }
    }
  }
  return 0;
}

void BM_AStar_Textbook(benchmark::State& state) {
  const std::string name = kAStarMaps[state.range(0)];
  const OccupancyGrid& g = Map("botlab/astar/" + name + ".map");
  const planning::ObstacleDistanceGrid d(g, {});
  const std::vector<Case> cases = ReadCases(name);
  size_t i = 0;
  for (auto _ : state) {
    const Case& c = cases[i++ % cases.size()];
    benchmark::DoNotOptimize(TextbookAStar(d, c.start, c.goal, 0.1));
  }
  state.SetLabel(name + " (per query, cases in turn)");
}

BENCHMARK(BM_AStar_Ours)->DenseRange(0, 4)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_AStar_Textbook)->DenseRange(0, 4)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
