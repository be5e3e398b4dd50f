#include "mbot/pipeline/pipeline.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <set>
#include <sstream>
#include <thread>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/log.hpp"
#include "mbot/msgs/sink.hpp"
#include "mbot/msgs/outputs.hpp"

namespace mbot::pipeline {

using msgs::Bus;
using msgs::RunContext;
using msgs::StageType;
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

// Delivers emitted events to the stages after the emitter, to the source's sink and to the outputs.
class PipelineBus : public Bus {
 public:
  PipelineBus(std::vector<std::pair<std::string, std::unique_ptr<Stage>>>& stages, msgs::Sink* sink,
              std::vector<std::unique_ptr<msgs::OutputRunner>>& outputs)
      : stages_(stages), sink_(sink), outputs_(outputs) {}
  void Emit(const Stage* from, const msgs::Event& event) override {
    for (auto& o : outputs_) o->Offer(event);
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
  bool Watched() const override { return !outputs_.empty(); }
  bool stop_requested() const { return stop_; }
  const std::string& reason() const { return reason_; }

 private:
  std::vector<std::pair<std::string, std::unique_ptr<Stage>>>& stages_;
  msgs::Sink* sink_;
  std::vector<std::unique_ptr<msgs::OutputRunner>>& outputs_;
  bool stop_ = false;
  std::string reason_;
};

// The section [name] that [pipeline] `key` lists: once, and not a reserved one.
config::Section ListedSection(const config::Config& config, const std::string& key, const std::string& what,
                              const std::string& name, std::set<std::string>* used) {
  if (used->count(name)) {
    config.GetSection("pipeline")
        .Fail(key, "'" + name +
                       "' is listed twice, or as a stage and an output, or is a "
                       "reserved section");
  }
  used->insert(name);
  if (!config.HasSection(name)) {
    config.GetSection("pipeline").Fail(key, what + " '" + name + "' has no [" + name + "] section");
  }
  return config.GetSection(name);
}

// The registered type the section's `type` names; an unknown one lists the known ones.
template <typename T, typename Find>
const T* FindListedType(config::Section& s, const std::string& what, Find find, const std::vector<const T*>& all) {
  const std::string type = s.RequireString("type", what + " type");
  const T* t = find(type);
  if (!t) {
    std::string known;
    for (const T* k : all) known += (known.empty() ? "" : ", ") + k->name;
    s.Fail("type", "unknown " + what + " type '" + type + "' (known: " + known + ")");
  }
  return t;
}

// Holds a recorded source's events to the playback's speed on the wall clock, and while paused.
class Pacer {
 public:
  explicit Pacer(const msgs::Playback& playback) : playback_(playback) {}
  void Wait(int64_t t_us, const std::atomic<bool>& stop) {
    using Clock = std::chrono::steady_clock;
    constexpr auto kStep = std::chrono::milliseconds(50);  // how soon a pause or a new speed is seen
    while (!stop.load()) {
      const uint64_t version = playback_.version();
      if (playback_.paused()) {
        anchored_ = false;
        std::this_thread::sleep_for(kStep);
        continue;
      }
      const double speed = playback_.speed();
      if (speed <= 0) return;
      if (!anchored_ || version != version_ || t_us < anchor_t_us_) {
        anchored_ = true, version_ = version, anchor_t_us_ = t_us, anchor_wall_ = Clock::now();
        return;
      }
      const auto due = anchor_wall_ + std::chrono::microseconds(static_cast<int64_t>((t_us - anchor_t_us_) / speed));
      const auto now = Clock::now();
      if (due <= now) return;
      std::this_thread::sleep_for(std::min<Clock::duration>(due - now, kStep));
    }
  }

 private:
  const msgs::Playback& playback_;
  bool anchored_ = false;
  uint64_t version_ = 0;
  int64_t anchor_t_us_ = 0;
  std::chrono::steady_clock::time_point anchor_wall_;
};

}  // namespace

PipelinePlan BuildPlan(const config::Config& config) {
  PipelinePlan plan;
  {
    config::Section s = config.GetSection("pipeline");
    plan.pipeline.stages = s.GetList("stages", {}, "the stage sections to run, in order");
    if (plan.pipeline.stages.empty()) s.Fail("stages", "names no stage (e.g. 'stages = inspect')");
    plan.pipeline.outputs = s.GetList("outputs", {},
                                      "output sections: every event of the run also goes to each (a bus, a viewer, a "
                                      "recorder), through its own queue (mbot_nav --list-outputs)");
    plan.pipeline.seed = static_cast<uint64_t>(s.GetInt("seed", 1, "seed of every random number generator", 0));
    plan.pipeline.progress = s.GetChoice("progress", "auto", {"auto", "bar", "lines", "off"},
                                         "progress display: a bar on a terminal, a line every 10% otherwise");
    plan.pipeline.max_events = s.GetInt("max_events", 0, "stop after this many events (0: the whole input)", 0);
    plan.pipeline.skip_events = s.GetInt("skip_events", 0,
                                         "read and drop the input's first events (a replay that starts later in a "
                                         "log; max_events counts after them)",
                                         0);
    plan.pipeline.playback_speed =
        s.GetDouble("playback_speed", 0.0,
                    "a recording plays this many times real time (0: as fast as it can; a viewer can pause it and "
                    "change it); live sources and the simulator are never paced here",
                    0.0, 1000.0);
    s.Finish();
  }
  {
    config::Section s = config.GetSection("output");
    plan.output.dir = s.GetPath("dir", plan.output.dir, "folder every output is written to (created if missing)");
    s.Finish();
  }
  {
    config::Section s = config.GetSection("source");
    plan.source = msgs::ParseSourceOptions(s);
    s.Finish();
  }
  std::set<std::string> used = {"pipeline", "output", "source", "viewer"};
  for (const std::string& name : plan.pipeline.stages) {
    config::Section s = ListedSection(config, "stages", "stage", name, &used);
    const StageType* st = FindListedType<StageType>(s, "stage", msgs::FindStageType, msgs::StageTypes());
    plan.stages.emplace_back(name, st->create(s));
    s.Finish();
  }
  for (const std::string& name : plan.pipeline.outputs) {
    config::Section s = ListedSection(config, "outputs", "output", name, &used);
    const msgs::OutputType* ot =
        FindListedType<msgs::OutputType>(s, "output", msgs::FindOutputType, msgs::OutputTypes());
    msgs::OutputOptions options = msgs::ParseOutputOptions(s, *ot);
    plan.outputs.push_back({name, ot->create(s), std::move(options)});
    s.Finish();
  }
  // [viewer] on any config (--set viewer.enabled=true): the live view, an output like the listed ones.
  if (config.HasSection("viewer")) {
    config::Section s = config.GetSection("viewer");
    const bool enabled = s.GetBool("enabled", false, "serve the live view: Foxglove WebSocket and the page");
    const msgs::OutputType* ot = msgs::FindOutputType("viewer");
    if (!ot) s.Fail("enabled", "this mbot_nav was built without the viewer (libs/viewer)");
    msgs::OutputOptions options = msgs::ParseOutputOptions(s, *ot);
    std::unique_ptr<msgs::Output> output = ot->create(s);
    s.Finish();
    if (enabled) plan.outputs.push_back({"viewer", std::move(output), std::move(options)});
  }
  // [record] on any config (--set record.format=mcap): the run recorded as a ROS 2 bag in the output
  // folder, unless a config lists its own [record] output.
  if (config.HasSection("record") && !used.count("record")) {
    used.insert("record");
    config::Section s = config.GetSection("record");
    const std::string format = s.GetChoice("format", "none", {"none", "mcap"},
                                           "record the run: none, or mcap (a ROS 2 bag: run.mcap and metadata.yaml "
                                           "in the output folder)");
    if (format == "mcap") {
      const msgs::OutputType* ot = msgs::FindOutputType("rosbag2");
      if (!ot) s.Fail("format", "this mbot_nav was built without the ROS 2 transport (libs/ros2)");
      msgs::OutputOptions options = msgs::ParseOutputOptions(s, *ot);
      std::unique_ptr<msgs::Output> output = ot->create(s);
      plan.outputs.push_back({"record", std::move(output), std::move(options)});
    }
    s.Finish();
  }
  for (const std::string& name : config.SectionNames()) {
    if (!used.count(name)) {
      throw config::ConfigError(
          config.SectionOrigin(name).ToString() + ": [" + name +
          "] is not used (not listed in [pipeline] stages or outputs, and not pipeline/output/source)");
    }
  }
  return plan;
}

bool SourceIsABus(const config::Config& config) {
  if (!config.HasSection("source")) return false;
  config::Section s = config.GetSection("source");  // a copy: the plan's own reading checks the keys
  if (!s.Has("type")) return false;
  const msgs::SourceType* t = msgs::FindSourceType(s.GetString("type", "auto", "input format"));
  return t && !t->default_url.empty();
}

RunSummary RunPlan(PipelinePlan& plan, const std::atomic<bool>& stop) {
  RunSummary summary;
  const auto wall0 = std::chrono::steady_clock::now();
  EnsureDirectory(plan.output.dir);
  plan.source.seed = plan.pipeline.seed;
  std::unique_ptr<msgs::Source> source = msgs::OpenSource(plan.source);
  std::vector<std::unique_ptr<msgs::OutputRunner>> outputs;
  for (auto& o : plan.outputs) {
    outputs.push_back(std::make_unique<msgs::OutputRunner>(o.name, std::move(o.output), o.options));
  }
  plan.outputs.clear();
  PipelineBus bus(plan.stages, source->sink(), outputs);
  msgs::Inbox inbox;
  msgs::Playback playback(plan.pipeline.playback_speed);
  msgs::Playback* recording = source->sink() ? nullptr : &playback;  // a live source is never held
  RunContext ctx{plan.output.dir,       plan.pipeline.seed, source.get(), plan.source.path, &bus,
                 &summary.event_result, source->sink(),     &inbox,       recording};
  for (auto& o : outputs) o->Open(ctx);
  for (auto& [name, stage] : plan.stages) stage->Start(ctx);
  // Every output says what it sent and dropped, also when the run fails.
  const auto close_outputs = [&](bool interrupted) {
    for (auto& o : outputs) {
      msgs::OutputCounts counts = o->Close(interrupted);
      mbot::log::Info("output " + o->name() + ": " + counts.ToString());
      summary.outputs.emplace_back(o->name(), std::move(counts));
    }
    outputs.clear();
  };

  Progress progress(plan.pipeline.progress);
  Pacer pacer(playback);
  int64_t t0 = 0, t_last = 0;
  // Every event of the run, the source's and what came back from the outputs' peers, goes to each
  // output and then to the stages in order.
  const auto dispatch = [&](const msgs::Event& e) {
    for (auto& o : outputs) o->Offer(e);
    for (auto& [name, stage] : plan.stages) stage->OnEvent(e);
  };
  try {
    for (long long i = 0; i < plan.pipeline.skip_events && !stop.load(); ++i) {
      if (!source->Next()) break;
    }
    while (!stop.load() && !bus.stop_requested()) {
      if (plan.pipeline.max_events > 0 && summary.events >= plan.pipeline.max_events) break;
      // What came from outside (a viewer's goal or teleop) goes in first, at the data's time.
      for (msgs::Event& in : inbox.Take()) {
        in.t_us = t_last;
        dispatch(in);
      }
      std::optional<msgs::Event> ev = source->Next();
      if (!ev) break;
      if (recording) pacer.Wait(ev->t_us, stop);
      if (summary.events == 0) t0 = ev->t_us;
      t_last = ev->t_us;
      ++summary.events;
      dispatch(*ev);
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
    close_outputs(true);
    throw;
  }
  summary.interrupted = stop.load();
  summary.stopped_by = bus.reason();
  if (const long long lost = inbox.dropped()) {
    mbot::log::Warn("pipeline: " + std::to_string(lost) +
                    " messages from outputs' peers (goals, teleop) dropped: "
                    "more came than the run took in");
  }
  progress.Update(source->Progress(), summary.events, summary.data_seconds, true);
  progress.Done();
  try {
    for (auto& [name, stage] : plan.stages) stage->Finish(ctx, summary.interrupted);
  } catch (...) {
    close_outputs(true);
    throw;
  }
  close_outputs(summary.interrupted);
  summary.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  if (summary.events == 0 && !summary.interrupted && source->events_expected()) {
    // Nothing passes silently: an empty file, or one whose every record was rejected, is a failed run.
    const msgs::SourceDiagnostics& d = source->diagnostics();
    throw std::runtime_error(plan.source.path + ": no usable event in the input (" + source->Format() + "; " +
                             std::to_string(d.rejected_messages) + " rejected, " + std::to_string(d.unknown_messages) +
                             " of unknown types" + (d.truncated_tail ? ", truncated" : "") + ")");
  }
  return summary;
}

}  // namespace mbot::pipeline
