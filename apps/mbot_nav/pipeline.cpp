#include "pipeline.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <set>
#include <sstream>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/log.hpp"
#include "mbot/drivers/sink.hpp"

namespace mbot::app {
namespace {

// A bar on a terminal, a line every 10% otherwise.
class Progress {
 public:
  explicit Progress(const std::string& mode) {
    const bool tty = ::isatty(2);
    bar_ = mode == "bar" || (mode == "auto" && tty);
    lines_ = mode == "lines" || (mode == "auto" && !tty);
  }
  void Update(double fraction, long long events, double data_s, bool force = false) {
    const auto now = std::chrono::steady_clock::now();
    if (bar_) {
      if (!force && now - last_ < std::chrono::milliseconds(100)) return;
      last_ = now;
      const int width = 30;
      const int filled = static_cast<int>(std::clamp(fraction, 0.0, 1.0) * width);
      std::fprintf(stderr, "\r[%s%s] %3.0f%%  %lld events  %.1f s of data", std::string(filled, '#').c_str(),
                   std::string(width - filled, '.').c_str(), 100.0 * fraction, events, data_s);
      std::fflush(stderr);
    } else if (lines_) {
      const int decile = static_cast<int>(fraction * 10.0);
      if (decile <= last_decile_ && !(force && decile < 10)) return;
      last_decile_ = decile;
      std::fprintf(stderr, "progress: %3.0f%%  %lld events  %.1f s of data\n", 100.0 * fraction, events, data_s);
    }
  }
  void Done() {
    if (bar_) std::fprintf(stderr, "\n");
  }

 private:
  bool bar_ = false;
  bool lines_ = false;
  int last_decile_ = 0;
  std::chrono::steady_clock::time_point last_{};
};

// Delivers emitted events to the stages after the emitter and to the sink.
class PipelineBus : public Bus {
 public:
  PipelineBus(std::vector<std::pair<std::string, std::unique_ptr<Stage>>>& stages, drivers::Sink* sink)
      : stages_(stages), sink_(sink) {}
  void Emit(const Stage* from, const drivers::Event& event) override {
    size_t i = 0;
    while (i < stages_.size() && stages_[i].second.get() != from) ++i;
    for (size_t j = i + 1; j < stages_.size(); ++j) stages_[j].second->OnEvent(event);
    if (sink_) sink_->Send(event);
  }
  void RequestStop(const std::string& reason) override {
    if (!stop_) mbot::log::Info("pipeline: stopping: " + reason);
    stop_ = true;
    if (reason_.empty()) reason_ = reason;
  }
  bool stop_requested() const { return stop_; }
  const std::string& reason() const { return reason_; }

 private:
  std::vector<std::pair<std::string, std::unique_ptr<Stage>>>& stages_;
  drivers::Sink* sink_;
  bool stop_ = false;
  std::string reason_;
};

}  // namespace

PipelinePlan BuildPlan(const config::Config& config) {
  PipelinePlan plan;
  {
    config::Section s = config.GetSection("pipeline");
    plan.pipeline.stages = s.GetList("stages", {}, "the stage sections to run, in order");
    if (plan.pipeline.stages.empty()) s.Fail("stages", "names no stage (e.g. 'stages = inspect')");
    plan.pipeline.seed = static_cast<uint64_t>(s.GetInt("seed", 1, "seed of every random number generator", 0));
    plan.pipeline.progress = s.GetChoice("progress", "auto", {"auto", "bar", "lines", "off"},
                                         "progress display: a bar on a terminal, a line every 10% otherwise");
    plan.pipeline.max_events = s.GetInt("max_events", 0, "stop after this many events (0: the whole input)", 0);
    s.Finish();
  }
  {
    config::Section s = config.GetSection("output");
    plan.output.dir = s.GetPath("dir", plan.output.dir, "folder every output is written to (created if missing)");
    s.Finish();
  }
  {
    config::Section s = config.GetSection("source");
    RegisterSources();
    plan.source = drivers::ParseSourceOptions(s);
    s.Finish();
  }
  std::set<std::string> used = {"pipeline", "output", "source"};
  for (const std::string& name : plan.pipeline.stages) {
    if (used.count(name)) {
      config.GetSection("pipeline").Fail("stages", "'" + name + "' is listed twice or is a reserved section");
    }
    used.insert(name);
    if (!config.HasSection(name)) {
      config.GetSection("pipeline").Fail("stages", "stage '" + name + "' has no [" + name + "] section");
    }
    config::Section s = config.GetSection(name);
    const std::string type = s.RequireString("type", "stage type");
    const StageType* st = FindStageType(type);
    if (!st) {
      std::string known;
      for (const auto& t : StageTypes()) known += (known.empty() ? "" : ", ") + t.name;
      s.Fail("type", "unknown stage type '" + type + "' (known: " + known + ")");
    }
    plan.stages.emplace_back(name, st->create(s));
    s.Finish();
  }
  for (const std::string& name : config.SectionNames()) {
    if (!used.count(name)) {
      throw config::ConfigError(config.SectionOrigin(name).ToString() + ": [" + name +
                                "] is not used (not listed in [pipeline] stages, and not pipeline/output/source)");
    }
  }
  return plan;
}

RunSummary RunPlan(PipelinePlan& plan, const std::atomic<bool>& stop) {
  RunSummary summary;
  const auto wall0 = std::chrono::steady_clock::now();
  EnsureDirectory(plan.output.dir);
  plan.source.seed = plan.pipeline.seed;
  std::unique_ptr<drivers::Source> source = drivers::OpenSource(plan.source);
  PipelineBus bus(plan.stages, source->sink());
  RunContext ctx{plan.output.dir,       plan.pipeline.seed, source.get(), plan.source.path, &bus,
                 &summary.event_result, source->sink()};
  for (auto& [name, stage] : plan.stages) stage->Start(ctx);

  Progress progress(plan.pipeline.progress);
  int64_t t0 = 0, t_last = 0;
  try {
    while (!stop.load() && !bus.stop_requested()) {
      if (plan.pipeline.max_events > 0 && summary.events >= plan.pipeline.max_events) break;
      std::optional<drivers::Event> ev = source->Next();
      if (!ev) break;
      if (summary.events == 0) t0 = ev->t_us;
      t_last = ev->t_us;
      ++summary.events;
      for (auto& [name, stage] : plan.stages) stage->OnEvent(*ev);
      summary.data_seconds = (t_last - t0) * 1e-6;
      progress.Update(source->Progress(), summary.events, summary.data_seconds);
    }
  } catch (...) {
    // Keep what was computed: every stage still writes its outputs, then the error goes up.
    progress.Done();
    for (auto& [name, stage] : plan.stages) {
      try {
        stage->Finish(ctx, true);
      } catch (const std::exception& e) {
        mbot::log::Error("stage " + name + ": " + e.what());
      }
    }
    throw;
  }
  summary.interrupted = stop.load();
  summary.stopped_by = bus.reason();
  progress.Update(source->Progress(), summary.events, summary.data_seconds, true);
  progress.Done();
  for (auto& [name, stage] : plan.stages) stage->Finish(ctx, summary.interrupted);
  summary.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  if (summary.events == 0 && !summary.interrupted && source->events_expected()) {
    // Nothing passes silently: an empty file, or one whose every record was rejected, is a failed run.
    const drivers::SourceDiagnostics& d = source->diagnostics();
    throw std::runtime_error(plan.source.path + ": no usable event in the input (" + source->Format() + "; " +
                             std::to_string(d.rejected_messages) + " rejected, " + std::to_string(d.unknown_messages) +
                             " of unknown types" + (d.truncated_tail ? ", truncated" : "") + ")");
  }
  return summary;
}

}  // namespace mbot::app
