#include "competition.hpp"

#include <cstdio>
#include <iostream>
#include <optional>
#include <filesystem>
#include <set>
#include <sstream>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/log.hpp"
#include "mbot/common/strings.hpp"
#include "mbot/mapping/log_odds_mapper.hpp"
#include "mbot/sim/hand_out.hpp"
#include "mbot/reports/competition_report.hpp"

namespace mbot::app {
namespace {

// Another world for an event: the organisers hand the team that world's inputs (libs/sim) through
// the event's own keys, read here with the event's settings.
void HandOutInputs(const std::string& world_path, const std::string& dir, bool waypoints_given, config::Config* event) {
  sim::EventSetup setup;
  setup.waypoints_given = waypoints_given;
  config::Section mission = event->GetSection("mission"), slam = event->GetSection("slam");
  setup.task = mission.Has("task") ? mission.GetString("task", "", "") : "";
  setup.localization = slam.Has("mode") && slam.GetString("mode", "", "") == "localization";
  setup.resolution_m = slam.GetDouble("resolution_m", mapping::MapperOptions{}.resolution_m, "", 0.001, 10.0);
  for (const std::string& s : sim::HandOut(sim::World::Load(world_path), world_path, setup, dir + "/known_map.map")) {
    event->Set(s);
  }
}

using Row = reports::CompetitionRow;

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
    const std::string waypoints = e.GetString(
        "waypoints", "", "the circuit on a world that names none (a map): x, y, theta_deg; … in the start's frame");
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
      if (!waypoints.empty()) event.Set("mission.waypoints=" + waypoints);
      for (const std::string& s : sets) event.Set(s);
    } catch (const config::ConfigError& err) {
      e.Fail("set", err.what());
    }
    if (!world.empty()) {
      // The world's inputs, handed out with the event's own settings (its task, SLAM's resolution);
      // an explicit `set` of the same keys still wins.
      try {
        HandOutInputs(world, plan.output_dir + "/" + name, !waypoints.empty(), &event);
        for (const std::string& s : sets) event.Set(s);
      } catch (const std::exception& err) {
        e.Fail("world", err.what());
      }
    }
    try {
      plan.events.push_back({name, pipeline::BuildPlan(event)});
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
    r.section = e.name;
    r.outputs = e.plan.output.dir;
    if (stop.load()) {
      r.result = "not run: interrupted";
      rows.push_back(r);
      continue;
    }
    mbot::log::Info("competition: " + e.name + " (seed " + std::to_string(e.plan.pipeline.seed) + ", world " +
                    e.plan.source.path + ")");
    try {
      const pipeline::RunSummary s = pipeline::RunPlan(e.plan, stop);
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

  std::cout << reports::CompetitionTable(rows, plan.not_run) << std::flush;
  EnsureDirectory(plan.output_dir);
  reports::WriteJson(plan.output_dir + "/competition.json", reports::CompetitionJson(rows, plan.not_run));
  return status;
}

}  // namespace mbot::app
