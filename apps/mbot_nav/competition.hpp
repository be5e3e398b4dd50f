// The competition: several events, each a pipeline of its own config (speed_run.ini,
// maze_explorer.ini, warehouse.ini), run one after another with one seed, and one score table.
// A config with a [competition] section describes it:
//   [competition]  events = <section names, in order>; seed; not_run = <"Event: why" lines>
//   [<event>]      config = <the event's INI>; optional world (its source.path), seed, and
//                  set = <section.key=value overrides of the event's config, separated by ';'>
//                  (event sections not listed in `events` are allowed and not run)
//   [output]       dir: each event writes to dir/<event>/, the table goes to dir/competition.json
#pragma once

#include <atomic>
#include <string>
#include <vector>

#include "mbot/common/config.hpp"
#include "mbot/pipeline/pipeline.hpp"
#include "stages/stages.hpp"

namespace mbot::app {

struct CompetitionEvent {
  std::string name;  // the section name
  pipeline::PipelinePlan plan;
};

struct CompetitionPlan {
  std::vector<CompetitionEvent> events;
  std::vector<std::string> not_run;  // "Heavy Lift: needs the forklift ..."
  std::string output_dir;
};

bool IsCompetition(const config::Config& config);

// Parses [competition], [output] and every event section, and builds every event's pipeline
// before anything runs, so a mistake in the last event's config stops the run at once. Throws
// config::ConfigError naming the file, section and key (the event's own file for its own keys).
CompetitionPlan BuildCompetition(const config::Config& config);

// Runs the events in order (after Ctrl-C the rest are skipped), prints the table and writes
// competition.json. Returns the exit status: 0, 1 when an event failed to run, 130 interrupted.
int RunCompetition(CompetitionPlan& plan, const std::atomic<bool>& stop);

}  // namespace mbot::app
