#include "sweep_mode.hpp"

#include <filesystem>
#include <iostream>
#include <map>

#include "mbot/sweep/sweep.hpp"
#include "mbot/pipeline/pipeline.hpp"

namespace mbot::app {

SweepPlan BuildSweep(const config::Config& config, const std::string& binary) {
  SweepPlan plan;
  plan.spec = sweep::ParseSweep(config, binary, std::filesystem::current_path().string());
  const sweep::SweepSpec& spec = plan.spec;
  std::vector<sweep::Job>& jobs = plan.jobs;
  try {
    jobs = sweep::ExpandJobs(spec);
  } catch (const std::invalid_argument& e) {
    throw config::ConfigError(spec.sweep_file + ": " + e.what());
  }
  // Every job's own run, parsed now as it will be then: a mistyped key fails here, not 200 jobs in.
  // (A generated maze's arena does not exist yet; its source is then checked by extension only.)
  std::map<std::string, config::Config> loaded;
  for (const sweep::Job& job : jobs) {
    for (const std::vector<std::string>& run : job.runs) {  // a maze's generation, then the run itself
      try {
        auto it = loaded.find(run[3]);
        if (it == loaded.end()) it = loaded.emplace(run[3], config::Config::Load(run[3])).first;
        config::Config c = it->second;
        for (size_t k = 4; k + 1 < run.size(); k += 2) c.Set(run[k + 1]);
        pipeline::BuildPlan(c);
      } catch (const std::exception& e) {
        throw config::ConfigError(spec.sweep_file + ": job " + job.id + " would fail: " + e.what());
      }
    }
  }
  return plan;
}

size_t WriteSweepJobs(const config::Config& config, const std::string& binary) {
  const SweepPlan plan = BuildSweep(config, binary);
  const sweep::SweepSpec& spec = plan.spec;
  const std::vector<sweep::Job>& jobs = plan.jobs;
  sweep::WriteSweep(spec, jobs);
  std::cout << "sweep " << spec.name << ": " << jobs.size() << " jobs in " << spec.output_dir
            << "/jobs.txt (and sweep.sbatch); nothing run. Run them with\n"
            << sweep::EngineCommands(spec);
  return jobs.size();
}

}  // namespace mbot::app
