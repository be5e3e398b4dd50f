// Sweeps as data: a [sweep] config names a base config and the axes (generated mazes, worlds, logs,
// seeds, `--set` grids, named cases) and expands to a job list — one shell command per run, each an
// ordinary mbot_nav run writing under the sweep folder — plus a Slurm array script. Nothing here
// runs a job: GNU parallel, Slurm or a shell runs the list unchanged (README, "Sweeps").
//
//   [sweep]  config = <base INI> (required); the axes, each optional:
//              mazes = 1-100 (generated-maze seeds; each job generates its maze with maze_config,
//              default generate_mazes.ini), worlds = a.arena, b.map, logs = x.log, y.log (these
//              three set world_key, default source.path; give one of them), seeds = 1-10 (seed_key,
//              default pipeline.seed), grid = slam.particles=200,300; mission.max_speed_m_s=0.3,0.5
//              (every combination), cases = <axis sections>;
//            set = <overrides of every job, ';'-separated>; outputs = score.json (what a complete
//            job has; merged); metrics = score.points.total, ... (the table's columns); retries = 2;
//            threads = 1 (OMP_NUM_THREADS per job); binary (default: the running mbot_nav);
//            slurm_partition, slurm_time, slurm_mem, slurm_job_name, slurm_lines_per_task = 1
//   [<case>] one key per value of that axis: `<value name> = config=<ini>; s.k=v; ...` (config=
//            optional: another base config for this value)
//   [output] dir: jobs.txt, jobs.tsv, sweep.json, sweep.sbatch, and jobs/<id>/ for each job
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace mbot::config {
class Config;
}

namespace mbot::sweep {

// One value of an axis: its name in job ids and tables, and what it does to a run.
struct AxisValue {
  std::string name;               // "7" (a generated maze's seed), "1", "300", "maze_1"
  std::vector<std::string> sets;  // section.key=value overrides
  std::string config;             // another base config for this value ("" keeps the sweep's)
};

struct Axis {
  std::string name;              // "maze", "world", "log", "seed", the grid key, the case section
  bool generated_mazes = false;  // each job generates the maze its value names, then runs on it
  std::vector<AxisValue> values;
};

struct SlurmOptions {
  std::string partition, time_limit, memory;  // empty: the cluster's defaults
  // Jobs per array task: T = ceil(jobs / k) tasks, task i runs lines i, i+T, i+2T, ... (strided, so
  // long and short jobs mix). Jobs of a second pay Slurm's scheduling cycle (a second or so per
  // task) once per k jobs instead of once per job.
  int lines_per_task = 1;
  std::string job_name = "mbot_sweep";
};

struct SweepSpec {
  std::string name;                       // the sweep config's file stem
  std::string sweep_file;                 // the [sweep] config, absolute
  std::string base_config;                // absolute
  std::string maze_config;                // generate_mazes.ini (absolute) for the maze axis
  std::string world_key = "source.path";  // the key a maze's arena, a world or a log goes to
  std::string seed_key = "pipeline.seed";
  std::vector<Axis> axes;                             // in the order of the job id: maze/world/log, cases, grid, seed
  std::vector<std::string> sets;                      // every job's overrides
  std::vector<std::string> outputs = {"score.json"};  // files (in the job folder) a complete job has
  std::vector<std::string> metrics;                   // "<file stem>.<json path>" in the merged table
  int retries = 2;  // extra attempts of a failed job (parallel --retries, Slurm requeue)
  // OpenMP threads per job (OMP_NUM_THREADS in each line; Slurm's --cpus-per-task). One: two jobs on
  // two cores run side by side, where two of two spinning threads each run 5x slower.
  int threads = 1;
  std::string binary;      // mbot_nav, absolute
  std::string workdir;     // where the jobs run (the expanding process's folder), absolute
  std::string output_dir;  // absolute
  SlurmOptions slurm;
};

struct Job {
  std::string id;                                         // "maze-7_seed-1"
  std::string dir;                                        // output_dir/jobs/<id>, absolute
  std::vector<std::pair<std::string, std::string>> axes;  // axis name, value name
  std::vector<std::vector<std::string>> runs;             // argv of each mbot_nav run, in order
  std::string command;                                    // the job's line of jobs.txt
};

bool IsSweep(const config::Config& config);

// Parses [sweep], [output] and the case sections strictly (any other section, unknown key, empty
// axis, bad range or duplicate value is a config::ConfigError naming file, line, section and key).
// `binary` is the mbot_nav the jobs run (absolute); `workdir` the folder they run in.
SweepSpec ParseSweep(const config::Config& config, const std::string& binary, const std::string& workdir);

// "1-6, 9, 12-14" -> 1..6, 9, 12..14 (in order written). Throws std::invalid_argument saying why.
std::vector<uint64_t> ParseRanges(const std::string& text);

// Every combination of the axes' values, in order (the first axis varies slowest).
std::vector<Job> ExpandJobs(const SweepSpec& spec);

// One word for a POSIX shell: single-quoted unless it is plain.
std::string ShellQuote(const std::string& word);

// Writes output_dir/jobs.txt (the lines), jobs.tsv (id, folder, axis values, command), sweep.json
// (the manifest the merge reads) and sweep.sbatch (a Slurm job array over jobs.txt), each whole or
// not at all, and creates output_dir/slurm/ for the array's logs.
void WriteSweep(const SweepSpec& spec, const std::vector<Job>& jobs);

// The commands that run the list (printed by mbot_nav after writing it).
std::string EngineCommands(const SweepSpec& spec);

}  // namespace mbot::sweep
