// A config with a [sweep] section (libs/sweep) expands to a job list and runs nothing:
//   mbot_nav --config config/sweep_mazes.ini --set sweep.mazes=1-6 --set output.dir=D
#pragma once

#include <string>
#include <vector>

#include "mbot/common/config.hpp"
#include "mbot/sweep/sweep.hpp"

namespace mbot::app {

struct SweepPlan {
  sweep::SweepSpec spec;
  std::vector<sweep::Job> jobs;
};

// Parses the sweep and expands it, and checks every job's configuration as the job's own run will
// (pipeline::BuildPlan). Throws config::ConfigError naming the file, section and key (and the job). Writes
// nothing.
SweepPlan BuildSweep(const config::Config& config, const std::string& binary);

// BuildSweep, then the job list (libs/sweep WriteSweep) and the commands that run it, on stdout.
// Returns the number of jobs.
size_t WriteSweepJobs(const config::Config& config, const std::string& binary);

}  // namespace mbot::app
