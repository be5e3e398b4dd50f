// mbot_nav: parse arguments, load the configuration, build the pipeline, run it, report.
#include <csignal>
#include <unistd.h>
#include <filesystem>
#include <cstring>
#include <iostream>
#include <cstdlib>
#include <optional>

#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "competition.hpp"
#include "mbot/pipeline/pipeline.hpp"
#include "mbot/msgs/outputs.hpp"
#include "mbot/sweep/sweep.hpp"
#include "stages/stages.hpp"
#include "sweep_mode.hpp"

namespace {

std::atomic<bool> g_stop{false};

void OnSignal(int) {
  if (g_stop.exchange(true)) std::_Exit(130);  // a second Ctrl-C: leave at once
}

constexpr const char* kUsage = R"(usage: mbot_nav --config FILE [--set section.key=value ...] [options]

Runs the pipeline that FILE describes: [pipeline] stages = ... names the stage sections, each with
type = <stage type> and its keys; [source] path = ... is the input; [output] dir = ... gets every
output. `${datasets}` in a value is the shared datasets folder (MBOT_DATASETS_DIR).
A FILE with a [competition] section runs several events, each its own pipeline config, and prints
one score table (config/competition.ini: --set competition.seed=N, --set <event>.world=FILE).
A FILE with a [sweep] section writes a job list (jobs.txt, sweep.sbatch) for GNU parallel or Slurm
and runs nothing (config/sweep_mazes.ini); config/merge_sweep.ini merges the jobs' results.

options:
  --config FILE          the INI file (include = other.ini pulls in shared defaults)
  --set S.K=V            override key K of section S (repeatable; applied after includes)
  --unset S.K            remove key K of section S that FILE or its includes set (repeatable;
                         e.g. source.carmen_order when graph_slam.ini replays a bag)
  --print-config         print the effective configuration and exit
  --list-stages          list the stage types with their keys and defaults and exit
  --list-sources         list the source types ([source] type) and what each reads, and exit
  --list-outputs         list the output types ([pipeline] outputs) with their keys, and exit
  --quiet                print warnings and errors only
  --version              print the version and exit
  --help                 this text

exit status: 0 done, 1 run-time error, 2 configuration or usage error, 130 interrupted (outputs written)
)";

void ListStages() {
  auto describe = [](const std::string& title, const std::string& doc, mbot::config::Section& s) {
    std::cout << title << "\n    " << doc << "\n";
    for (const auto& k : s.docs()) {
      std::cout << "    " << k.key << " (" << k.type
                << ") = " << (k.required ? std::string("<required>") : k.default_value) << "\n        " << k.doc
                << "\n";
    }
    std::cout << "\n";
  };
  {
    auto s = mbot::config::Section::Describe("source");
    mbot::msgs::ParseSourceOptions(s);
    describe("[source]", "the input dataset (mbot_nav --list-sources for the types)", s);
  }
  for (const mbot::msgs::StageType* t : mbot::msgs::StageTypes()) {
    auto s = mbot::config::Section::Describe(t->name);
    t->create(s);
    describe("stage type " + t->name, t->doc, s);
  }
}

void ListOutputs() {
  std::cout << "[pipeline] outputs = <sections>: each names its type (one of these) and its keys; every output\n"
               "also takes channels, max_rate_hz, queue_per_kind and when_full.\n\n";
  for (const mbot::msgs::OutputType* t : mbot::msgs::OutputTypes()) {
    auto s = mbot::config::Section::Describe(t->name);
    mbot::msgs::ParseOutputOptions(s, *t);
    t->create(s);
    std::cout << "output type " << t->name << "\n    " << t->doc << "\n";
    for (const auto& k : s.docs()) {
      std::cout << "    " << k.key << " (" << k.type << ") = " << k.default_value << "\n        " << k.doc << "\n";
    }
    std::cout << "\n";
  }
}

// The running binary, absolute (the sweep's jobs run this one).
std::string SelfPath(const char* argv0) {
  std::error_code ec;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::filesystem::absolute(argv0).string() : self.string();
}

void ListSources() {
  std::cout << "[source] type = auto detects the type from the path and the file's content; the types:\n";
  for (const auto& t : mbot::msgs::SourceTypes()) std::cout << "  " << t.name << "\n      " << t.doc << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  mbot::app::RegisterAll();
  std::string config_path;
  std::vector<std::string> sets, unsets;
  bool print_config = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](const char* flag) -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "mbot_nav: " << flag << " needs a value\n" << kUsage;
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      std::cout << kUsage;
      return 0;
    } else if (a == "--version") {
      std::cout << "mbot_nav " << MBOT_NAV_VERSION << "\n";
      return 0;
    } else if (a == "--config") {
      config_path = value("--config");
    } else if (a == "--set") {
      sets.push_back(value("--set"));
    } else if (a.rfind("--set=", 0) == 0) {
      sets.push_back(a.substr(6));
    } else if (a == "--unset") {
      unsets.push_back(value("--unset"));
    } else if (a == "--print-config") {
      print_config = true;
    } else if (a == "--list-stages") {
      ListStages();
      return 0;
    } else if (a == "--list-sources") {
      ListSources();
      return 0;
    } else if (a == "--list-outputs") {
      ListOutputs();
      return 0;
    } else if (a == "--quiet") {
      mbot::log::SetLevel(mbot::log::Level::kWarn);
    } else {
      std::cerr << "mbot_nav: unknown argument '" << a << "'\n" << kUsage;
      return 2;
    }
  }
  if (config_path.empty()) {
    std::cerr << "mbot_nav: --config FILE is required\n" << kUsage;
    return 2;
  }

  mbot::pipeline::PipelinePlan plan;
  std::optional<mbot::app::CompetitionPlan> competition;
  try {
    auto config = mbot::config::Config::Load(config_path);
    for (const auto& u : unsets) config.Unset(u);
    for (const auto& s : sets) config.Set(s);
    if (print_config) {
      std::cout << config.ToIni();
      return 0;
    }
    if (mbot::sweep::IsSweep(config)) {
      mbot::app::WriteSweepJobs(config, SelfPath(argv[0]));
      return 0;
    }
    if (!mbot::app::IsCompetition(config) && mbot::pipeline::SourceIsABus(config) && !std::getenv("OMP_WAIT_POLICY")) {
      // A robot's bus: OpenMP threads sleep between scans (pipeline.hpp says why). The policy is read
      // when libgomp loads, so the process starts again with it, before any of the plan is built; if
      // that fails it runs as it is.
      if (setenv("OMP_WAIT_POLICY", "PASSIVE", 1) == 0) execv("/proc/self/exe", argv);
    }
    if (mbot::app::IsCompetition(config)) {
      competition = mbot::app::BuildCompetition(config);
    } else {
      plan = mbot::pipeline::BuildPlan(config);
    }
  } catch (const mbot::config::ConfigError& e) {
    std::cerr << "mbot_nav: configuration error: " << e.what() << "\n";
    return 2;
  } catch (const std::runtime_error& e) {  // a file the configuration names that cannot be read
    std::cerr << "mbot_nav: configuration error: " << e.what() << "\n";
    return 2;
  }

  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  if (competition) {
    const int status = mbot::app::RunCompetition(*competition, g_stop);
    std::fprintf(stderr, "%s: %d warnings; outputs in %s\n",
                 status == 130 ? "interrupted"
                 : status      ? "failed"
                               : "done",
                 mbot::log::WarningCount(), competition->output_dir.c_str());
    return status;
  }
  try {
    const auto summary = mbot::pipeline::RunPlan(plan, g_stop);
    std::fprintf(stderr,
                 "%s: %lld events, %.1f s of data in %.2f s wall (%.0fx real time), %d warnings; outputs in %s\n",
                 summary.interrupted ? "interrupted" : "done", summary.events, summary.data_seconds,
                 summary.wall_seconds, summary.wall_seconds > 0 ? summary.data_seconds / summary.wall_seconds : 0.0,
                 mbot::log::WarningCount(), plan.output.dir.c_str());
    return summary.interrupted ? 130 : 0;
  } catch (const std::exception& e) {
    std::cerr << "mbot_nav: error: " << e.what() << "\n";
    return 1;
  }
}
