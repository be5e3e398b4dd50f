#include "competition.hpp"

#include <cstdio>
#include <iomanip>
#include <iostream>
#include <optional>
#include <filesystem>
#include <set>
#include <sstream>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/log.hpp"
#include "mbot/common/strings.hpp"
#include "mbot/sim/hand_out.hpp"
#include "stages/report.hpp"

namespace mbot::app {
namespace {

// Another world for an event: the organisers hand the team that world's inputs (libs/sim) through
// the event's own keys, read here with the event's settings.
void HandOutInputs(const std::string& world_path, const std::string& dir, config::Config* event) {
  sim::EventSetup setup;
  config::Section mission = event->GetSection("mission"), slam = event->GetSection("slam");
  setup.task = mission.Has("task") ? mission.GetString("task", "", "") : "";
  setup.localization = slam.Has("mode") && slam.GetString("mode", "", "") == "localization";
  setup.resolution_m = slam.GetDouble("resolution_m", mapping::MapperOptions{}.resolution_m, "", 0.001, 10.0);
  for (const std::string& s : sim::HandOut(sim::World::Load(world_path), world_path, setup, dir + "/known_map.map")) {
    event->Set(s);
  }
}

struct Row {
  std::string name, result, outputs;  // the section, what became of it, where its outputs are
  std::optional<EventResult> scored;  // the referee's result
};

}  // namespace

bool IsCompetition(const config::Config& config) { return config.HasSection("competition"); }

CompetitionPlan BuildCompetition(const config::Config& config) {
  CompetitionPlan plan;
  config::Section c = config.GetSection("competition");
  const std::vector<std::string> events = c.GetList("events", {}, "the event sections to run, in order");
  if (events.empty() && !c.describing()) c.Fail("events", "names no event");
  const long long seed = c.GetInt("seed", 1, "the seed every event runs with (an event's own seed key wins)", 0);
  plan.not_run = c.GetList("not_run", {}, "events listed in the table as not run, as 'Event: why'");
  c.Finish();
  {
    config::Section o = config.GetSection("output");
    plan.output_dir =
        o.GetPath("dir", "out/competition", "each event writes to dir/<event>; the table to dir/competition.json");
    o.Finish();
  }
  std::set<std::string> used = {"competition", "output"};
  for (const std::string& name : events) {
    if (!used.insert(name).second) c.Fail("events", "'" + name + "' is listed twice or is a reserved section");
    if (!config.HasSection(name)) c.Fail("events", "event '" + name + "' has no [" + name + "] section");
  }
  // Event sections not listed in `events` are allowed (competition.events=warehouse runs one of
  // them); any other section is a mistake.
  for (const std::string& name : config.SectionNames()) {
    if (!used.count(name) && !config.GetSection(name).Has("config")) {
      throw config::ConfigError(config.SectionOrigin(name).ToString() + ": [" + name +
                                "] is not used (not an event section with a config key, and not competition/output)");
    }
  }
  for (const std::string& name : events) {
    config::Section e = config.GetSection(name);
    const std::string path = e.RequirePath("config", "the event's own configuration (an INI a single run takes)");
    const std::string world =
        e.GetPath("world", "", "another world for the event (its [source] path: an arena or a map)");
    const long long event_seed = e.GetInt("seed", seed, "this event's seed", 0);
    const std::string set_text =
        e.GetString("set", "", "section.key=value overrides of the event's configuration, separated by ';'");
    e.Finish();
    const std::vector<std::string> sets = SplitTrimmed(set_text, ';');
    if (!world.empty() && !std::filesystem::exists(world)) e.Fail("world", world + ": no such file");
    config::Config event;
    try {
      event = config::Config::Load(path);
    } catch (const config::ConfigError& err) {
      e.Fail("config", err.what());
    }
    try {
      event.Set("pipeline.seed=" + std::to_string(event_seed));
      event.Set("pipeline.progress=off");  // the events are short; the table is the report
      event.Set("output.dir=" + plan.output_dir + "/" + name);
      if (!world.empty()) event.Set("source.path=" + world);
      for (const std::string& s : sets) event.Set(s);
    } catch (const config::ConfigError& err) {
      e.Fail("set", err.what());
    }
    if (!world.empty()) {
      // The world's inputs, handed out with the event's own settings (its task, SLAM's resolution);
      // an explicit `set` of the same keys still wins.
      try {
        HandOutInputs(world, plan.output_dir + "/" + name, &event);
        for (const std::string& s : sets) event.Set(s);
      } catch (const std::exception& err) {
        e.Fail("world", err.what());
      }
    }
    try {
      plan.events.push_back({name, BuildPlan(event)});
    } catch (const config::ConfigError& err) {
      throw config::ConfigError(config.SectionOrigin(name).ToString() + ": [" + name + "] (config = " + path +
                                ", with this section's seed, world and set): " + err.what());
    }
  }
  return plan;
}

int RunCompetition(CompetitionPlan& plan, const std::atomic<bool>& stop) {
  std::vector<Row> rows;
  int status = 0;
  for (CompetitionEvent& e : plan.events) {
    Row r;
    r.name = e.name;
    r.outputs = e.plan.output.dir;
    if (stop.load()) {
      r.result = "not run: interrupted";
      rows.push_back(r);
      continue;
    }
    mbot::log::Info("competition: " + e.name + " (seed " + std::to_string(e.plan.pipeline.seed) + ", world " +
                    e.plan.source.path + ")");
    try {
      const RunSummary s = RunPlan(e.plan, stop);
      r.scored = s.event_result;
      if (r.scored) r.result = s.interrupted ? "interrupted" : r.scored->result;
      if (!r.scored) r.result = "not scored (the referee of " + e.name + " reported no score)";
      if (s.interrupted) status = 130;
    } catch (const std::exception& ex) {
      mbot::log::Error("competition: " + e.name + ": " + ex.what());
      r.result = std::string("error: ") + ex.what();
      status = status ? status : 1;
    }
    rows.push_back(r);
  }

  int total = 0, max_total = 0;
  bool incomplete = false;  // an event that should have scored did not
  std::ostringstream t;
  t << "\nCompetition on the simulator (Winter 2024 rules)\n"
    << std::left << std::setw(15) << "event" << std::setw(22) << "arena" << std::setw(6) << "seed" << std::setw(12)
    << "result" << std::right << std::setw(8) << "time s" << std::setw(11) << "points" << std::setw(6) << "hits"
    << std::setw(7) << "RTF"
    << "\n";
  for (const Row& r : rows) {
    if (!r.scored) {
      incomplete = true;
      t << std::left << std::setw(15) << r.name << r.result << "\n";
      continue;
    }
    const EventResult& e = *r.scored;
    total += e.points, max_total += e.max_points;
    t << std::left << std::setw(15) << e.event << std::setw(22) << e.arena.substr(0, 21) << std::setw(6) << e.seed
      << std::setw(12) << r.result.substr(0, 11) << std::right << std::setw(8) << Num(e.time_s, 4) << std::setw(11)
      << (std::to_string(e.points) + " / " + std::to_string(e.max_points)) << std::setw(6) << e.collisions
      << std::setw(6) << Num(e.real_time_factor, 3) << "x\n";
  }
  for (const std::string& n : plan.not_run) {
    const auto colon = n.find(':');
    t << std::left << std::setw(15) << n.substr(0, colon) << "not run"
      << (colon == std::string::npos ? "" : ":" + n.substr(colon + 1)) << "\n";
  }
  t << std::left << std::setw(63) << "total" << std::right << std::setw(11)
    << (std::to_string(total) + " / " + std::to_string(max_total))
    << (incomplete ? "  (incomplete: an event above has no score)" : "") << "\n";
  std::cout << t.str() << std::flush;

  std::ostringstream j;
  j << "{\n  \"events\": [";
  for (size_t i = 0; i < rows.size(); ++i) {
    const Row& r = rows[i];
    const std::optional<EventResult>& e = r.scored;
    auto num = [&](double v, int digits = 6) { return e ? Num(v, digits) : std::string("null"); };
    j << (i ? "," : "") << "\n    {\"section\": " << JsonString(r.name)
      << ", \"event\": " << JsonString(e ? e->event : "") << ", \"arena\": " << JsonString(e ? e->arena : "")
      << ", \"seed\": " << (e ? std::to_string(e->seed) : "null") << ", \"result\": " << JsonString(r.result)
      << ", \"time_s\": " << num(e ? e->time_s : 0.0, 4) << ", \"points\": " << num(e ? e->points : 0)
      << ", \"max_points\": " << num(e ? e->max_points : 0) << ", \"collisions\": " << num(e ? e->collisions : 0)
      << ", \"real_time_factor\": " << num(e ? e->real_time_factor : 0.0, 3)
      << ", \"outputs\": " << JsonString(r.outputs) << "}";
  }
  j << "\n  ],\n  \"not_run\": [";
  for (size_t i = 0; i < plan.not_run.size(); ++i) j << (i ? ", " : "") << JsonString(plan.not_run[i]);
  j << "],\n  \"points\": " << total << ",\n  \"max_points\": " << max_total
    << ",\n  \"complete\": " << (incomplete ? "false" : "true") << "\n}\n";
  EnsureDirectory(plan.output_dir);
  WriteFileAtomically(plan.output_dir + "/competition.json", [&](std::ostream& out) { out << j.str(); });
  return status;
}

}  // namespace mbot::app
