// SLAM benchmarks (Google Benchmark) on the real legacy botlab log sweep_drive_square_10mx10m_5cm:
//  - particle-filter update per scan at 100 … 100000 particles: ours (mbot::mapping::ParticleFilter,
//    likelihood field, all cores and one thread) beside MRPT 2.5's CMonteCarloLocalization2D
//    (likelihood field "Thrun", standard proposal, systematic resampling) on the same map, scans,
//    odometry and particle counts;
//  - log-odds map update: scans inserted per second at 0.05 m;
//  - the lookup bound: a plain likelihood-lookup loop (random poses, a 200 x 200 float table, 209
//    beams, one core) over as many particle-beam pairs as the filter weighs, the floor the filter's
//    update is compared with (issue 20); its counter evals_per_s is particle-beam lookups a second.
// Every timed iteration starts from the raw scan, so turning it into the filter's points (our
// DeskewScan + Prepare; MRPT's observation object and the point cloud it caches) is timed on both
// sides. Wall time is reported (UseRealTime) because our filter runs on several threads.
// Run: build/tests/mbot_slam_benchmark [--benchmark_filter=ParticleFilter]
//      [--benchmark_repetitions=5 --benchmark_report_aggregates_only=true]
// Data: $MBOT_DATASETS_DIR, else the configured MBOT_DATASETS_DIR; missing data skips with an error.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <iterator>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <mrpt/bayes/CParticleFilter.h>
#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/random/RandomGenerators.h>
#include <mrpt/slam/CMonteCarloLocalization2D.h>

#include "mbot/common/config.hpp"
#include "mbot/drivers/map_io.hpp"
#include "mbot/drivers/source_options.hpp"
#include "mbot/lcm/lcm_sources.hpp"
#include "mbot/mapping/action_model.hpp"
#include "mbot/mapping/log_odds_mapper.hpp"
#include "mbot/mapping/moving_scan.hpp"
#include "mbot/mapping/particle_filter.hpp"
#include "mbot/mapping/sensor_model.hpp"

namespace {

namespace drivers = mbot::drivers;
namespace msgs = mbot::msgs;
namespace mapping = mbot::mapping;
using mbot::motion::Pose2D;

const char* kMap = "botlab/legacy_2017/maps/sweep_drive_square_10mx10m_5cm.map";
const char* kLog = "botlab/legacy_2017/sweep_drive_square_10mx10m_5cm.log";
constexpr uint64_t kSeed = 1;
constexpr double kMinRangeM = mapping::ScanOptions{}.min_range_m;

// One legacy scan as MRPT wants it: evenly spaced beams, counter-clockwise, centred on the sensor's x
// axis, with a validity flag per beam.
struct EvenScan {
  std::vector<float> ranges;
  std::vector<char> valid;
  float aperture = 0.0f;
  float max_range_m = 0.0f;
};

// The log reduced to what the filters consume: the scans at which a filter would update (odometry
// moved enough since the previous one, as in slam.cpp) with the odometry pose nearest each in time.
struct LogData {
  std::string error;  // non-empty: the data could not be read
  mapping::OccupancyGrid map;
  std::vector<msgs::LidarScan> scans;
  std::vector<Pose2D> odometry;
  std::vector<EvenScan> even_scans;
  size_t beams_max = 0;
};

// MRPT places beam i of n at -aperture/2 + i·aperture/(n-1). With aperture = 2π(n-1)/n the beams are
// 2π/n apart and cover the full circle exactly once (aperture 2π would put two beams at ±π). Each of
// our beams goes to the nearest of those angles; if two land on one, the shorter range wins.
EvenScan ToEvenScan(const msgs::LidarScan& scan) {
  const size_t n = scan.ranges_m.size();
  EvenScan out;
  out.ranges.assign(n, 0.0f);
  out.valid.assign(n, 0);
  out.max_range_m = scan.max_range_m > 0 ? scan.max_range_m : 10.0f;
  if (n < 2) return out;
  const double step = 2.0 * M_PI / static_cast<double>(n);
  out.aperture = static_cast<float>(step * static_cast<double>(n - 1));
  for (size_t i = 0; i < n; ++i) {
    const float r = scan.ranges_m[i];
    // The same beams our side keeps as hits: a return, not too close, short of the maximum.
    if (!std::isfinite(r) || r < kMinRangeM || r >= out.max_range_m) continue;
    const double a = mbot::motion::WrapAngle(scan.angles_rad[i]);
    const long k = std::lround((a + 0.5 * out.aperture) / step);
    const size_t bin = static_cast<size_t>(((k % static_cast<long>(n)) + static_cast<long>(n)) % static_cast<long>(n));
    if (!out.valid[bin] || r < out.ranges[bin]) {
      out.ranges[bin] = r;
      out.valid[bin] = 1;
    }
  }
  return out;
}

LogData Load() {
  LogData d;
  try {
    const std::string dir = mbot::config::DatasetsDir();
    d.map = drivers::ReadBotlabMap(dir + "/" + kMap);

    msgs::SourceOptions options;
    options.path = dir + "/" + kLog;
    auto source = msgs::OpenSource(options);
    std::vector<std::pair<int64_t, msgs::LidarScan>> scans;
    std::vector<mbot::motion::TimedPose> odometry;
    while (auto event = source->Next()) {
      if (event->kind == msgs::EventKind::kLidar) {
        if (auto* scan = std::get_if<msgs::LidarScan>(&event->payload)) scans.emplace_back(event->t_us, *scan);
      } else if (event->kind == msgs::EventKind::kOdometry) {
        if (auto* pose = std::get_if<Pose2D>(&event->payload)) odometry.push_back({event->t_us, *pose});
      }
    }
    if (scans.empty() || odometry.empty()) {
      d.error = options.path + ": no lidar scans or no odometry";
      return d;
    }

    const mapping::ActionModel action{mapping::ActionModelOptions{}};
    for (auto& [t_us, scan] : scans) {
      // Source events come in time order, so the odometry series is sorted.
      auto it = std::lower_bound(odometry.begin(), odometry.end(), t_us,
                                 [](const mbot::motion::TimedPose& p, int64_t t) { return p.t_us < t; });
      if (it == odometry.end() || (it != odometry.begin() && t_us - std::prev(it)->t_us < it->t_us - t_us)) --it;
      if (!d.odometry.empty() && !action.Moved(d.odometry.back(), it->pose)) continue;
      d.beams_max = std::max(d.beams_max, scan.ranges_m.size());
      d.even_scans.push_back(ToEvenScan(scan));
      d.scans.push_back(std::move(scan));
      d.odometry.push_back(it->pose);
    }
    if (d.scans.size() < 2) d.error = options.path + ": fewer than two scans with motion";
  } catch (const std::exception& e) {
    d.error = e.what();
  }
  return d;
}

const LogData& Data() {
  static const LogData data = Load();
  return data;
}

// Skips the benchmark (with the reason) when the data is missing; true when it may run.
bool HaveData(benchmark::State& state) {
  if (Data().error.empty()) return true;
  state.SkipWithError(("dataset unavailable: " + Data().error).c_str());
  return false;
}

// Walks the scans in order, from the second on (each needs the step from the one before it). At the
// end of the log the filter is put back at the start (untimed), so it never jumps across the log.
class ScanCycle {
 public:
  explicit ScanCycle(size_t scans) : scans_(scans) {}
  // The index of the next scan to process; `restart` is set when the filter must be reset first.
  size_t Next(bool* restart) {
    *restart = next_ >= scans_;
    if (*restart) next_ = 1;
    return next_++;
  }

 private:
  size_t scans_;
  size_t next_ = 1;
};

std::vector<mapping::ScanRay> Rays(const msgs::LidarScan& scan) {
  return mapping::DeskewScan(scan.ranges_m, scan.angles_rad, {}, Pose2D{}, Pose2D{}, scan.max_range_m,
                             mapping::ScanOptions{});
}

// `odom_gap_m`: how far the filter's estimate ended from the odometry pose of the last scan it took;
// `odom_gap_max_m`: the largest such gap over every timed update. Not accuracy figures (the map frame
// only roughly matches odometry; 0.26 m at most over whole runs of every case), a check that the
// filter tracked the log all along: a filter that lost the robot spends its time differently. The
// last gap alone depended on where the timed loop stopped; the maximum shows any lapse in between.
void Label(benchmark::State& state, int particles, const std::string& what, const Pose2D& estimate,
           const Pose2D& odometry, double max_gap) {
  state.counters["particles"] = particles;
  state.counters["odom_gap_m"] = std::hypot(estimate.x - odometry.x, estimate.y - odometry.y);
  state.counters["odom_gap_max_m"] = max_gap;
  state.SetLabel(what + ", " + std::to_string(Data().scans.size()) +
                 " scans of <= " + std::to_string(Data().beams_max) + " beams");
}

// Args: particle count, threads (0: all cores).
void RunOurFilter(benchmark::State& state, bool simd) {
  if (!HaveData(state)) return;
  const LogData& d = Data();
  const int particles = static_cast<int>(state.range(0));
  const int threads = static_cast<int>(state.range(1));

  mapping::SensorModelOptions sensor_options;
  sensor_options.simd = simd;
  mapping::SensorModel sensor{sensor_options};
  sensor.SetMap(d.map);
  const mapping::ActionModel action{mapping::ActionModelOptions{}};
  mapping::ParticleFilterOptions options;
  options.particles = particles;
  options.threads = threads;
  mapping::ParticleFilter filter(options, kSeed);
  filter.InitializeAt(d.odometry[0], 0.05, 0.05);

  // Each scan's end points are prepared before timing (deskew and ray ends, the same work for any
  // particle count: BM_ScanPrepare times it); the loop times the filter's update alone.
  std::vector<mapping::ScanPoints> points(d.scans.size());
  for (size_t k = 0; k < d.scans.size(); ++k) points[k] = sensor.Prepare(Rays(d.scans[k]));
  ScanCycle cycle(d.scans.size());
  size_t last = 0;
  double max_gap = 0.0;
  for (auto _ : state) {
    bool restart = false;
    const size_t i = last = cycle.Next(&restart);
    if (restart) {
      state.PauseTiming();
      filter.InitializeAt(d.odometry[0], 0.05, 0.05);
      state.ResumeTiming();
    }
    const mapping::OdometryStep step = mapping::ActionModel::StepBetween(d.odometry[i - 1], d.odometry[i]);
    const mapping::FilterStatus status = filter.Update(action, step, sensor, points[i]);
    max_gap = std::max(max_gap, std::hypot(status.pose.x - d.odometry[i].x, status.pose.y - d.odometry[i].y));
  }
  Label(state, particles,
        std::string(threads == 1 ? "ours, 1 thread" : "ours, all cores") +
            (simd && mapping::SensorModel::SimdAvailable() ? ", AVX2" : ", scalar"),
        filter.status().pose, d.odometry[last], max_gap);
}
void BM_ParticleFilter_Ours(benchmark::State& state) { RunOurFilter(state, true); }
// The same without the AVX2 weighing (what a processor without AVX2 runs).
void BM_ParticleFilter_OursScalar(benchmark::State& state) { RunOurFilter(state, false); }

// What each scan costs before the filter sees it, whatever the particle count: deskew and the
// end points the sensor model weighs.
void BM_ScanPrepare(benchmark::State& state) {
  if (!HaveData(state)) return;
  const LogData& d = Data();
  mapping::SensorModel sensor{mapping::SensorModelOptions{}};
  sensor.SetMap(d.map);
  size_t i = 0;
  for (auto _ : state) {
    const mapping::ScanPoints points = sensor.Prepare(Rays(d.scans[i++ % d.scans.size()]));
    benchmark::DoNotOptimize(points.x.data());
  }
}

// MRPT's grid from ours: same extent and cells. MRPT cells hold the probability of being FREE, and
// its likelihood field treats cells below 0.5 as obstacles, so occupied (> 0) / free (< 0) / unknown
// map to 0.05 / 0.95 / 0.5 and both filters see exactly the same obstacle set.
std::shared_ptr<mrpt::maps::COccupancyGridMap2D> ToMrptMap(const mapping::OccupancyGrid& g) {
  auto m = std::make_shared<mrpt::maps::COccupancyGridMap2D>();
  const double res = g.resolution();
  m->setSize(static_cast<float>(g.origin_x()), static_cast<float>(g.origin_x() + g.width() * res),
             static_cast<float>(g.origin_y()), static_cast<float>(g.origin_y() + g.height() * res),
             static_cast<float>(res), 0.5f);
  for (int y = 0; y < g.height(); ++y) {
    for (int x = 0; x < g.width(); ++x) {
      const int8_t l = g.at(x, y);
      m->setCell(x, y, l > 0 ? 0.05f : l < 0 ? 0.95f : 0.5f);
    }
  }
  return m;
}

mrpt::poses::CPose2D ToMrpt(const Pose2D& p) { return {p.x, p.y, p.theta}; }

// Args: particle count.
void BM_ParticleFilter_MRPT(benchmark::State& state) {
  if (!HaveData(state)) return;
  const LogData& d = Data();
  const int particles = static_cast<int>(state.range(0));

  const auto map = ToMrptMap(d.map);
  if (static_cast<int>(map->getSizeX()) != d.map.width() || static_cast<int>(map->getSizeY()) != d.map.height()) {
    state.SkipWithError("MRPT grid size differs from the botlab map");
    return;
  }
  // Parameters as close to ours as MRPT allows: every beam (MRPT decimates 1 in 5 by default), the
  // same σ, the same 0.5 m search/clamp distance and uniform share.
  const mapping::SensorModelOptions ours;
  auto& lo = map->likelihoodOptions;
  lo.likelihoodMethod = mrpt::maps::COccupancyGridMap2D::lmLikelihoodField_Thrun;
  lo.LF_decimation = 1;
  lo.LF_stdHit = static_cast<float>(ours.sigma_m);
  lo.LF_maxCorrsDistance = static_cast<float>(ours.max_distance_m);
  lo.LF_zRandom = static_cast<float>(ours.random_weight);
  lo.LF_zHit = 1.0f - lo.LF_zRandom;
  lo.LF_maxRange = d.even_scans[0].max_range_m;

  mrpt::random::getRandomGenerator().randomize(kSeed);
  mrpt::slam::CMonteCarloLocalization2D pdf(particles);
  pdf.options.metricMap = map;
  // A uniform box of ±0.05 m and ±0.05 rad around the start, like our InitializeAt(pose, 0.05, 0.05).
  const auto reset = [&] { pdf.resetAroundSetOfPoses({ToMrpt(d.odometry[0]).asTPose()}, particles, 0.1, 0.1, 0.1); };
  reset();

  mrpt::bayes::CParticleFilter pf;
  pf.m_options.PF_algorithm = mrpt::bayes::CParticleFilter::pfStandardProposal;
  pf.m_options.resamplingMethod = mrpt::bayes::CParticleFilter::prSystematic;
  pf.m_options.adaptiveSampleSize = false;
  // ESS is in [0, 1]: BETA above 1 resamples on every update, as our filter does.
  pf.m_options.BETA = 1.1;

  mrpt::obs::CActionRobotMovement2D::TMotionModelOptions motion;
  motion.modelSelection = mrpt::obs::CActionRobotMovement2D::mmGaussian;

  ScanCycle cycle(d.scans.size());
  size_t last = 0;
  for (auto _ : state) {
    bool restart = false;
    const size_t i = last = cycle.Next(&restart);
    if (restart) {
      state.PauseTiming();
      reset();
      state.ResumeTiming();
    }
    // A fresh observation per scan, as a driver would deliver it: MRPT builds the scan's point
    // cloud inside its update and caches it in the observation, so that part cannot be timed apart
    // (ours is, BM_ScanPrepare; it is tens of microseconds against MRPT's milliseconds).
    const EvenScan& even = d.even_scans[i];
    auto scan = std::make_shared<mrpt::obs::CObservation2DRangeScan>();
    scan->aperture = even.aperture;
    scan->rightToLeft = true;
    scan->maxRange = even.max_range_m;
    scan->resizeScan(even.ranges.size());
    for (size_t b = 0; b < even.ranges.size(); ++b) {
      scan->setScanRange(b, even.ranges[b]);
      scan->setScanRangeValidity(b, even.valid[b] != 0);
    }
    mrpt::obs::CSensoryFrame frame;
    frame.insert(scan);

    mrpt::obs::CActionRobotMovement2D move;
    move.computeFromOdometry(ToMrpt(d.odometry[i]) - ToMrpt(d.odometry[i - 1]), motion);
    mrpt::obs::CActionCollection actions;
    actions.insert(move);

    pf.executeOn(pdf, &actions, &frame);
    benchmark::DoNotOptimize(pdf.size());
  }
  mrpt::poses::CPose2D mean;
  pdf.getMean(mean);
  Label(state, particles, "MRPT CMonteCarloLocalization2D, 1 thread", Pose2D{mean.x(), mean.y(), mean.phi()},
        d.odometry[last], NAN);  // not tracked per update: MRPT's mean costs a pass over the particles
}

// Steady-state insertion: one mapper keeps taking the log's scans in turn, at their odometry poses.
void BM_MapUpdate_LogOdds(benchmark::State& state) {
  if (!HaveData(state)) return;
  const LogData& d = Data();
  mapping::MapperOptions options;
  options.resolution_m = 0.05;
  mapping::LogOddsMapper mapper(options);
  size_t i = 0;
  for (auto _ : state) {
    const size_t k = i++ % d.scans.size();
    mapper.Insert(Rays(d.scans[k]), d.odometry[k]);
    benchmark::DoNotOptimize(mapper.map().cells().data());
  }
  state.SetItemsProcessed(state.iterations());
  state.SetLabel("scans at 0.05 m, deskew + insert, " + std::to_string(d.scans.size()) + " scans");
}

const int64_t kParticleCounts[] = {100, 500, 1000, 10000, 100000};

// Args: particle count. One core, no filter: for each random pose, rotate and translate 209 beam end
// points into a 200 x 200 table and sum what they hit (clamped to the table) — the work of weighing
// a particle, with nothing else.
void BM_LookupBound(benchmark::State& state) {
  const int particles = static_cast<int>(state.range(0));
  constexpr int kSide = 200, kBeams = 209;
  std::mt19937 rng(kSeed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<float> table(kSide * kSide);
  for (float& v : table) v = -unit(rng);
  std::vector<float> bx(kBeams), by(kBeams);
  for (int k = 0; k < kBeams; ++k) {
    const float a = 6.2831853f * k / kBeams, r = 5.0f + 40.0f * unit(rng);  // ranges in cells
    bx[k] = r * std::cos(a), by[k] = r * std::sin(a);
  }
  struct P {
    float x, y, c, s;
  };
  std::vector<P> poses(particles);
  for (P& p : poses) {
    const float th = 6.2831853f * unit(rng);
    p = {50.0f + 100.0f * unit(rng), 50.0f + 100.0f * unit(rng), std::cos(th), std::sin(th)};
  }
  std::vector<float> weight(particles);
  for (auto _ : state) {
    for (int i = 0; i < particles; ++i) {
      const P& p = poses[i];
      float acc = 0.0f;
      for (int k = 0; k < kBeams; ++k) {
        const int cx = std::min(kSide - 1, std::max(0, static_cast<int>(p.x + p.c * bx[k] - p.s * by[k])));
        const int cy = std::min(kSide - 1, std::max(0, static_cast<int>(p.y + p.s * bx[k] + p.c * by[k])));
        acc += table[cy * kSide + cx];
      }
      weight[i] = acc;
    }
    benchmark::DoNotOptimize(weight.data());
    benchmark::ClobberMemory();
  }
  state.counters["particles"] = particles;
  state.counters["evals_per_s"] =
      benchmark::Counter(static_cast<double>(particles) * kBeams, benchmark::Counter::kIsIterationInvariantRate);
}

void OursArgs(benchmark::internal::Benchmark* b) {
  for (int64_t threads : {0, 1}) {
    for (int64_t n : kParticleCounts) b->Args({n, threads});
  }
}

void MrptArgs(benchmark::internal::Benchmark* b) {
  for (int64_t n : kParticleCounts) b->Args({n});
}

BENCHMARK(BM_ParticleFilter_Ours)
    ->Apply(OursArgs)
    ->ArgNames({"particles", "threads"})
    ->UseRealTime()
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ParticleFilter_OursScalar)
    ->Args({1000, 1})
    ->Args({100000, 1})
    ->ArgNames({"particles", "threads"})
    ->UseRealTime()
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ParticleFilter_MRPT)
    ->Apply(MrptArgs)
    ->ArgNames({"particles"})
    ->UseRealTime()
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_MapUpdate_LogOdds)->UseRealTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ScanPrepare)->UseRealTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_LookupBound)->Apply(MrptArgs)->ArgNames({"particles"})->UseRealTime()->Unit(benchmark::kMicrosecond);

// Prints, after the usual table, the ratios the performance targets are stated in, from the runs of
// this same invocation (medians when --benchmark_repetitions is given): our whole update on one
// thread against the lookup loop's bound, and MRPT's update against ours on one thread.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      if (r.run_type == Run::RT_Iteration && !r.error_occurred)
        times_[r.benchmark_name()].push_back(r.GetAdjustedRealTime());
    }
    ConsoleReporter::ReportRuns(runs);
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    bool header = false;
    for (int64_t n : kParticleCounts) {
      const std::string p = "particles:" + std::to_string(n);
      const double ours = Median("BM_ParticleFilter_Ours/" + p + "/threads:1/real_time");
      const double bound = Median("BM_LookupBound/" + p + "/real_time");
      const double mrpt = Median("BM_ParticleFilter_MRPT/" + p + "/real_time");
      if (!(ours > 0) || (!(bound > 0) && !(mrpt > 0))) continue;
      if (!header) {
        std::printf("\n%-10s %14s %14s %14s %12s %12s\n", "particles", "ours 1 thread", "lookup bound", "MRPT",
                    "ours/bound", "MRPT/ours");
        header = true;
      }
      auto cell = [](double v) { return v > 0 ? v : NAN; };
      std::printf("%-10lld %14.1f %14.1f %14.1f %12.2f %12.1f\n", static_cast<long long>(n), ours, cell(bound),
                  cell(mrpt), cell(bound) > 0 ? ours / bound : NAN, cell(mrpt) > 0 ? mrpt / ours : NAN);
    }
    if (header) std::printf("(real time per update, us; ratios from this run)\n");
  }

 private:
  double Median(const std::string& name) const {
    auto it = times_.find(name);
    if (it == times_.end() || it->second.empty()) return 0.0;
    std::vector<double> v = it->second;
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  }
  std::map<std::string, std::vector<double>> times_;
};

}  // namespace

int main(int argc, char** argv) {
  mbot::drivers::RegisterDatasetSources();
  mbot::lcmio::RegisterLcmTransport();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
