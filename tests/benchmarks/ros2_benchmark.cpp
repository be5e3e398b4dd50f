// MCAP read throughput of the `mcap` source: every message of a bag read, decompressed and decoded
// into the pipeline's events (scripts/bench_mcap.sh makes the bag — the Intel log's ROS 1 bag
// converted by rosbags-convert — and sets MBOT_MCAP_BAG, and times Foxglove's and rosbags' Python
// readers on the same bag).
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <string>

#include "mbot/msgs/source.hpp"
#include "mbot/ros2/ros2_transport.hpp"

namespace {

void BM_McapSourceReadsTheBag(benchmark::State& state) {
  const char* bag = std::getenv("MBOT_MCAP_BAG");
  if (!bag) {
    state.SkipWithError("MBOT_MCAP_BAG is not set (scripts/bench_mcap.sh sets it)");
    return;
  }
  mbot::msgs::SourceOptions o;
  o.type = "mcap";
  o.path = bag;
  long long messages = 0, events = 0;
  for (auto _ : state) {
    std::unique_ptr<mbot::msgs::Source> source = mbot::msgs::OpenSource(o);
    while (auto e = source->Next()) {
      benchmark::DoNotOptimize(e->t_us);
      ++events;
    }
    messages += std::stoll(source->Details()[1].second);  // "messages": every record the reader met
  }
  state.SetItemsProcessed(messages);
  state.counters["events"] = benchmark::Counter(double(events) / double(state.iterations()));
}
BENCHMARK(BM_McapSourceReadsTheBag)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  mbot::ros2::RegisterRos2Transport();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
