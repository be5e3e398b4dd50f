#include "mbot/sweep/sweep.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <filesystem>
#include <set>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/common/strings.hpp"

namespace fs = std::filesystem;

namespace mbot::sweep {
namespace {

std::string Absolute(const std::string& path, const std::string& base) {
  if (path.empty()) return path;
  fs::path p(path);
  if (p.is_relative()) p = fs::path(base) / p;
  return p.lexically_normal().string();
}

// A value name fit for a folder name: letters, digits, '.', '-', '+'; anything else becomes '_'.
std::string PlainName(const std::string& text) {
  std::string out;
  for (char c : text) {
    const bool plain = std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '+';
    out += plain ? c : '_';
  }
  return out.empty() ? "_" : out;
}

std::string FileStem(const std::string& path) {
  std::string stem = fs::path(path).filename().string();
  for (const char* ext : {".gz", ".arena", ".map", ".yaml", ".pgm", ".log", ".clf", ".rawlog", ".bag", ".mcap"}) {
    if (EndsWith(stem, ext) && stem.size() > std::string(ext).size())
      stem.resize(stem.size() - std::string(ext).size());
  }
  return stem;
}

// `key=value` with key `section.key`: the override must name a section and a key.
void CheckAssignment(config::Section& s, const std::string& key, const std::string& item) {
  const size_t eq = item.find('=');
  const size_t dot = item.find('.');
  if (eq == std::string::npos || dot == std::string::npos || dot > eq || dot == 0 || dot + 1 == eq) {
    s.Fail(key, "'" + item + "' is not section.key=value");
  }
}

void CheckUnique(config::Section& s, const std::string& key, const Axis& axis) {
  std::set<std::string> seen;
  for (const AxisValue& v : axis.values) {
    if (!seen.insert(v.name).second) s.Fail(key, "value '" + v.name + "' appears twice (job ids would clash)");
  }
}

// What makes a job's recorded result its own: FNV-1a over its runs' words and the text of every
// configuration they name (an edited base config or another binary re-runs the job).
std::string JobStamp(const std::vector<std::vector<std::string>>& runs) {
  uint64_t h = 1469598103934665603ull;
  auto add = [&](const std::string& text) {
    for (unsigned char c : text) h = (h ^ c) * 1099511628211ull;
    h = (h ^ 0xff) * 1099511628211ull;
  };
  for (const auto& run : runs) {
    for (size_t k = 0; k < run.size(); ++k) {
      add(run[k]);
      if (k > 0 && run[k - 1] == "--config") {
        std::ifstream in(run[k], std::ios::binary);
        std::ostringstream text;
        text << in.rdbuf();
        add(text.str());
      }
    }
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

void WriteText(const std::string& path, const std::string& text) {
  WriteFileAtomically(path, [&](std::ostream& f) { f << text; });
}

}  // namespace

bool IsSweep(const config::Config& config) { return config.HasSection("sweep"); }

std::vector<uint64_t> ParseRanges(const std::string& text) {
  std::vector<uint64_t> out;
  for (const std::string& item : SplitTrimmed(text, ',')) {
    auto number = [&](const std::string& t) -> uint64_t {
      const std::string n = Trim(t);
      if (n.empty() || n.size() > 18 || n.find_first_not_of("0123456789") != std::string::npos) {
        throw std::invalid_argument("'" + item + "' is not a number or a range a-b of numbers below 10^18");
      }
      return std::stoull(n);
    };
    const size_t dash = item.find('-');
    if (dash == std::string::npos) {
      out.push_back(number(item));
      continue;
    }
    const uint64_t a = number(item.substr(0, dash)), b = number(item.substr(dash + 1));
    if (b < a) throw std::invalid_argument("range '" + item + "' runs backwards");
    if (b - a >= 100000) throw std::invalid_argument("range '" + item + "' has more than 100000 values");
    for (uint64_t v = a; v <= b; ++v) out.push_back(v);
  }
  if (out.empty()) throw std::invalid_argument("names no value");
  return out;
}

std::string ShellQuote(const std::string& word) {
  if (!word.empty() &&
      word.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-.,/:=+@%") ==
          std::string::npos) {
    return word;
  }
  std::string out = "'";
  for (char c : word) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

SweepSpec ParseSweep(const config::Config& config, const std::string& binary, const std::string& workdir) {
  SweepSpec spec;
  spec.binary = binary;
  spec.workdir = workdir;
  spec.sweep_file = Absolute(config.main_file(), workdir);
  spec.name = FileStem(spec.sweep_file);
  if (EndsWith(spec.name, ".ini")) spec.name.resize(spec.name.size() - 4);
  config::Section s = config.GetSection("sweep");
  spec.base_config =
      Absolute(s.GetPath("config", "", "the base configuration every job runs (an INI a single run takes)"), workdir);
  spec.maze_config =
      Absolute(s.GetPath("maze_config", (fs::path(spec.sweep_file).parent_path() / "generate_mazes.ini").string(),
                         "the maze generator's configuration (its style; default: generate_mazes.ini beside the sweep "
                         "config); each job of the maze axis generates its maze"),
               workdir);
  spec.world_key = s.GetString("world_key", spec.world_key, "the key a generated maze, a world or a log is set to");
  spec.seed_key = s.GetString("seed_key", spec.seed_key, "the key a seed is set to");
  const std::string mazes = s.GetString("mazes", "", "generated-maze axis: maze seeds, e.g. 1-100 or 1-6, 9");
  // Paths and grids expand ${datasets} and ${config_dir} like every path key.
  const std::vector<std::string> worlds = SplitTrimmed(s.GetPath("worlds", "", "world axis: arena or map files"), ',');
  const std::vector<std::string> logs =
      SplitTrimmed(s.GetPath("logs", "", "log axis: datasets (LCM, CARMEN, rawlog, ...)"), ',');
  const std::string seeds = s.GetString("seeds", "", "seed axis: seeds, e.g. 1-10 (none: the base config's seed)");
  const std::string grid =
      s.GetPath("grid", "", "--set grids: 'section.key=v1,v2,...' axes separated by ';' (every combination)");
  const std::vector<std::string> cases =
      s.GetList("cases", {}, "axis sections: each key of one is a value, `name = [config=<ini>;] s.k=v; ...`");
  const std::string set_text = s.GetPath("set", "", "overrides of every job, section.key=value separated by ';'");
  spec.outputs =
      s.GetList("outputs", spec.outputs, "files in a job's folder that a complete job has (and the merge reads)");
  spec.metrics =
      s.GetList("metrics", {}, "the merged table's columns: <output file stem>.<json path>, e.g. score.points.total");
  spec.retries = static_cast<int>(s.GetInt("retries", spec.retries, "extra attempts of a failed job", 0, 100));
  const std::string own_binary = s.GetPath("binary", "", "the mbot_nav the jobs run (default: this one)");
  if (!own_binary.empty()) spec.binary = Absolute(own_binary, workdir);
  spec.slurm.partition = s.GetString("slurm_partition", "", "Slurm partition (default: the cluster's)");
  spec.slurm.time_limit = s.GetString("slurm_time", "", "Slurm time limit per job, e.g. 00:30:00");
  spec.slurm.memory = s.GetString("slurm_mem", "", "Slurm memory per job, e.g. 2G");
  spec.threads = static_cast<int>(s.GetInt("threads", spec.threads,
                                           "threads per job (OMP_NUM_THREADS, Slurm --cpus-per-task); 1 fills every "
                                           "core with jobs",
                                           1, 1024));
  spec.slurm.job_name = s.GetString("slurm_job_name", spec.slurm.job_name, "Slurm job name");
  spec.slurm.lines_per_task =
      static_cast<int>(s.GetInt("slurm_lines_per_task", spec.slurm.lines_per_task,
                                "jobs each array task runs one after another, strided: of T tasks, task i runs lines "
                                "i, i+T, ... (short jobs: fewer tasks, less scheduling)",
                                1, 100000));
  s.Finish();
  for (auto [key, value] : {std::pair{"slurm_partition", &spec.slurm.partition},
                            {"slurm_time", &spec.slurm.time_limit},
                            {"slurm_mem", &spec.slurm.memory},
                            {"slurm_job_name", &spec.slurm.job_name}}) {
    if (value->find_first_of(" \t\r\n%\"'\\") != std::string::npos) {
      s.Fail(key, "'" + *value + "' has a space, quote, backslash or %: it cannot stand in an #SBATCH line");
    }
  }
  if (spec.base_config.empty()) s.Fail("config", "required key is missing (the base configuration)");
  if (!fs::is_regular_file(spec.base_config)) s.Fail("config", spec.base_config + ": no such file");
  if (spec.outputs.empty()) s.Fail("outputs", "names no file");
  for (const std::string& o : spec.outputs) {
    if (o.find('/') != std::string::npos || !EndsWith(o, ".json"))
      s.Fail("outputs", "'" + o + "' is not a .json file name");
  }
  for (const std::string& m : spec.metrics) {
    const size_t dot = m.find('.');
    const std::string file = m.substr(0, dot) + ".json";
    if (dot == std::string::npos || std::find(spec.outputs.begin(), spec.outputs.end(), file) == spec.outputs.end())
      s.Fail("metrics", "'" + m + "' must be <stem of one of the outputs>.<json path>");
  }
  for (const std::string& key : {spec.world_key, spec.seed_key}) {
    if (key.find('.') == std::string::npos)
      s.Fail(key == spec.world_key ? "world_key" : "seed_key", "'" + key + "' is not section.key");
  }
  {
    config::Section o = config.GetSection("output");
    spec.output_dir =
        Absolute(o.GetPath("dir", "out/" + spec.name, "the sweep folder: the job list, and jobs/<id>/"), workdir);
    o.Finish();
    // Slurm reads --output unquoted and expands % in it; a job line is one line of jobs.txt.
    if (spec.output_dir.find_first_of(" \t\r\n%") != std::string::npos) {
      o.Fail("dir", "'" + spec.output_dir + "' has a space or %: Slurm's #SBATCH --output cannot hold it");
    }
  }
  for (const std::string& item : SplitTrimmed(set_text, ';')) {
    CheckAssignment(s, "set", item);
    spec.sets.push_back(item);
  }

  const int world_axes = !mazes.empty() + !worlds.empty() + !logs.empty();
  if (world_axes > 1)
    s.Fail(!logs.empty() ? "logs" : "worlds", "mazes, worlds and logs all set " + spec.world_key + ": give one");
  if (!mazes.empty()) {
    if (!fs::is_regular_file(spec.maze_config)) s.Fail("maze_config", spec.maze_config + ": no such file");
    Axis a{"maze", true, {}};
    try {
      for (uint64_t m : ParseRanges(mazes)) {
        // The maze generator's seeds are ints (maze_generator first_seed).
        if (m > 2147483647u) throw std::invalid_argument("maze " + std::to_string(m) + " is above 2147483647");
        a.values.push_back({std::to_string(m), {}, ""});
      }
    } catch (const std::invalid_argument& e) {
      s.Fail("mazes", e.what());
    }
    CheckUnique(s, "mazes", a);
    spec.axes.push_back(a);
  }
  for (auto [key, files, name] : {std::tuple{"worlds", &worlds, "world"}, std::tuple{"logs", &logs, "log"}}) {
    if (files->empty()) continue;
    Axis a{name, false, {}};
    for (const std::string& f : *files) {
      const std::string path = Absolute(f, workdir);
      if (!fs::exists(path)) s.Fail(key, path + ": no such file");
      a.values.push_back({PlainName(FileStem(path)), {spec.world_key + "=" + path}, ""});
    }
    CheckUnique(s, key, a);
    spec.axes.push_back(a);
  }
  std::set<std::string> names;
  for (const std::string& section : cases) {
    if (section == "sweep" || section == "output" || !names.insert(section).second)
      s.Fail("cases", "'" + section + "' is listed twice or is a reserved section");
    if (!config.HasSection(section)) s.Fail("cases", "case axis '" + section + "' has no [" + section + "] section");
    config::Section c = config.GetSection(section);
    Axis a{section, false, {}};
    for (const std::string& value : c.Keys()) {
      AxisValue v{PlainName(value), {}, ""};
      if (v.name != value) c.Fail(value, "a value name takes letters, digits, '.', '-' and '+' only");
      for (const std::string& item : SplitTrimmed(c.GetPath(value, "", "a value of this axis"), ';')) {
        if (item.rfind("config=", 0) == 0) {
          v.config = Absolute(Trim(item.substr(7)), workdir);
          if (!fs::is_regular_file(v.config)) c.Fail(value, v.config + ": no such file");
        } else {
          CheckAssignment(c, value, item);
          v.sets.push_back(item);
        }
      }
      a.values.push_back(v);
    }
    c.Finish();
    if (a.values.empty()) s.Fail("cases", "[" + section + "] has no value");
    spec.axes.push_back(a);
  }
  for (const std::string& item : SplitTrimmed(grid, ';')) {
    CheckAssignment(s, "grid", item);
    const size_t eq = item.find('=');
    const std::string key = Trim(item.substr(0, eq));
    Axis a{key, false, {}};
    for (const std::string& value : SplitTrimmed(item.substr(eq + 1), ',')) {
      a.values.push_back({PlainName(value), {key + "=" + value}, ""});
    }
    if (a.values.empty()) s.Fail("grid", "'" + key + "' has no value");
    if (!names.insert(key).second) s.Fail("grid", "'" + key + "' is a grid axis twice");
    CheckUnique(s, "grid", a);
    spec.axes.push_back(a);
  }
  if (!seeds.empty()) {
    Axis a{"seed", false, {}};
    try {
      for (uint64_t v : ParseRanges(seeds))
        a.values.push_back({std::to_string(v), {spec.seed_key + "=" + std::to_string(v)}, ""});
    } catch (const std::invalid_argument& e) {
      s.Fail("seeds", e.what());
    }
    CheckUnique(s, "seeds", a);
    spec.axes.push_back(a);
  }
  // Axis names become column names and job-id parts: two of one name would mix their values.
  std::set<std::string> axis_names;
  for (const Axis& a : spec.axes) {
    if (!axis_names.insert(a.name).second) s.Fail("cases", "two axes are called '" + a.name + "'");
  }
  for (const std::string& section : config.SectionNames()) {
    if (section != "sweep" && section != "output" && !names.count(section)) {
      throw config::ConfigError(
          config.SectionOrigin(section).ToString() + ": [" + section +
          "] is not used (a sweep config holds [sweep], [output] and the sections its cases name)");
    }
  }
  return spec;
}

std::vector<Job> ExpandJobs(const SweepSpec& spec) {
  size_t total = 1;
  for (const Axis& a : spec.axes) {
    total *= a.values.size();
    if (total > 1000000) throw std::invalid_argument("sweep: more than 1000000 jobs");
  }
  std::vector<Job> jobs;
  jobs.reserve(total);
  std::vector<size_t> index(spec.axes.size(), 0);
  for (size_t n = 0; n < total; ++n) {
    // Mixed-radix count, the last axis fastest.
    size_t rest = n;
    for (size_t k = spec.axes.size(); k-- > 0;) {
      index[k] = rest % spec.axes[k].values.size();
      rest /= spec.axes[k].values.size();
    }
    Job job;
    std::string config = spec.base_config;
    std::vector<std::string> sets = spec.sets;
    const AxisValue* maze = nullptr;
    for (size_t k = 0; k < spec.axes.size(); ++k) {
      const Axis& axis = spec.axes[k];
      const AxisValue& v = axis.values[index[k]];
      job.axes.emplace_back(axis.name, v.name);
      job.id += (job.id.empty() ? "" : "_") + PlainName(axis.name) + "-" + v.name;
      if (!v.config.empty()) config = v.config;
      sets.insert(sets.end(), v.sets.begin(), v.sets.end());
      if (axis.generated_mazes) maze = &v;
    }
    if (job.id.empty()) job.id = "run";
    job.dir = spec.output_dir + "/jobs/" + job.id;
    if (maze) {
      const std::string world = job.dir + "/world";
      job.runs.push_back({spec.binary, "--quiet", "--config", spec.maze_config, "--set",
                          "mazes.first_seed=" + maze->name, "--set", "mazes.count=1", "--set", "mazes.png=false",
                          "--set", "mazes.basename=maze", "--set", "output.dir=" + world});
      // The world key first: a case or grid value may still override it.
      sets.insert(sets.begin(), spec.world_key + "=" + world + "/maze_" + maze->name + ".arena");
    }
    std::vector<std::string> run = {spec.binary, "--quiet", "--config", config};
    for (const std::string& s : sets) run.insert(run.end(), {"--set", s});
    run.insert(run.end(), {"--set", "pipeline.progress=off", "--set", "output.dir=" + job.dir});
    job.runs.push_back(run);
    for (const auto& r : job.runs) {
      for (const std::string& w : r) {
        if (w.find_first_of("\n\r\t") != std::string::npos) {
          throw std::invalid_argument("job " + job.id + ": '" + w +
                                      "' holds a line break or tab (a job is one line of jobs.txt)");
        }
      }
    }
    if (job.id.size() > 200) throw std::invalid_argument("job id " + job.id + " is over 200 characters");

    // The line: skip when complete (exit status 0 recorded by this very command, with configs of the
    // same text, and every output there), else run with the log in the job's folder, record the exit
    // status with the stamp, and exit with it.
    const std::string stamp = JobStamp(job.runs);
    const std::string q = ShellQuote(job.dir);
    std::ostringstream line;
    line << "cd " << ShellQuote(spec.workdir) << " && export OMP_NUM_THREADS=" << spec.threads << " && if [ \"$(cat "
         << q << "/exit_status 2>/dev/null)\" = '0 " << stamp << "' ]";
    for (const std::string& o : spec.outputs) line << " && [ -f " << q << "/" << ShellQuote(o) << " ]";
    line << "; then echo " << ShellQuote(job.id + ": complete, skipped") << "; else mkdir -p " << q << " && rm -f " << q
         << "/exit_status && {";
    for (size_t r = 0; r < job.runs.size(); ++r) {
      line << (r ? " &&" : "");
      for (const std::string& w : job.runs[r]) line << " " << ShellQuote(w);
    }
    line << "; } > " << q << "/job.log 2>&1; s=$?; echo \"$s " << stamp << "\" > " << q
         << "/exit_status; [ $s = 0 ]; fi";
    job.command = line.str();
    jobs.push_back(std::move(job));
  }
  std::map<std::string, size_t> ids;
  for (size_t k = 0; k < jobs.size(); ++k) {
    if (auto [it, fresh] = ids.emplace(jobs[k].id, k); !fresh) {
      throw std::invalid_argument("jobs " + std::to_string(it->second + 1) + " and " + std::to_string(k + 1) +
                                  " are both called " + jobs[k].id +
                                  " (value names with '_' or '-' run into each other): rename a value");
    }
  }
  return jobs;
}

std::string EngineCommands(const SweepSpec& spec) {
  const std::string d = ShellQuote(spec.output_dir);
  const std::string t = std::to_string(spec.threads);
  const std::string jobs = spec.threads > 1 ? " -j $(( $(nproc) >= " + t + " ? $(nproc) / " + t + " : 1 ))" : "";
  return "  GNU parallel (all cores): parallel" + jobs + " --retries " + std::to_string(spec.retries + 1) +
         " --joblog " + d + "/parallel.log -a " + d + "/jobs.txt\n" + "  Slurm (job array):        sbatch " + d +
         "/sweep.sbatch\n" + "  one after another:        bash " + d + "/jobs.txt\n" +
         "  then the table:           mbot_nav --config " + "config/merge_sweep.ini --set source.path=" + d + "\n";
}

void WriteSweep(const SweepSpec& spec, const std::vector<Job>& jobs) {
  EnsureDirectory(spec.output_dir);
  EnsureDirectory(spec.output_dir + "/slurm");
  std::ostringstream txt, tsv;
  tsv << "id\tdir";
  for (const Axis& a : spec.axes) tsv << "\t" << a.name;
  tsv << "\tcommand\n";
  nlohmann::ordered_json manifest;
  manifest["name"] = spec.name;
  manifest["sweep_config"] = spec.sweep_file;
  manifest["base_config"] = spec.base_config;
  manifest["outputs"] = spec.outputs;
  manifest["metrics"] = spec.metrics;
  manifest["retries"] = spec.retries;
  manifest["threads"] = spec.threads;
  manifest["slurm_lines_per_task"] = spec.slurm.lines_per_task;
  manifest["axes"] = nlohmann::ordered_json::array();
  for (const Axis& a : spec.axes) {
    nlohmann::ordered_json values = nlohmann::ordered_json::array();
    for (const AxisValue& v : a.values) values.push_back(v.name);
    manifest["axes"].push_back({{"name", a.name}, {"values", values}});
  }
  manifest["jobs"] = nlohmann::ordered_json::array();
  for (const Job& j : jobs) {
    txt << j.command << "\n";
    tsv << j.id << "\t" << j.dir;
    nlohmann::ordered_json axes;
    for (const auto& [axis, value] : j.axes) {
      tsv << "\t" << value;
      axes[axis] = value;
    }
    tsv << "\t" << j.command << "\n";
    manifest["jobs"].push_back({{"id", j.id}, {"dir", j.dir}, {"axes", axes}, {"command", j.command}});
  }
  const std::string d = spec.output_dir;
  const size_t per = static_cast<size_t>(spec.slurm.lines_per_task);
  const size_t tasks = std::max<size_t>(1, (jobs.size() + per - 1) / per);
  if (tasks > 1000) {
    log::Warn("sweep: sweep.sbatch is an array of " + std::to_string(tasks) +
              " tasks, past Slurm's default MaxArraySize (1001); raise [sweep] slurm_lines_per_task if the cluster "
              "keeps that default");
  }
  std::ostringstream sb;
  sb << "#!/bin/bash\n"
     << "# Slurm job array over " << jobs.size() << " jobs of " << spec.sweep_file << ".\n"
     << "# Submit: sbatch " << ShellQuote(d + "/sweep.sbatch")
     << "   (the folder must be on a filesystem the nodes share)\n"
     << "# Task N of the " << tasks << " runs line"
     << (per > 1 ? "s N, N+" + std::to_string(tasks) + ", N+2*" + std::to_string(tasks) + ", ..." : " N")
     << " of jobs.txt (strided: long and short jobs mix). A pre-empted\n"
     << "# task is requeued (--requeue); a failed one requeues itself up to " << spec.retries
     << " times and then runs only its\n"
     << "# incomplete jobs (Slurm delays a requeued task's start by about two minutes).\n"
     << "#SBATCH --job-name=" << spec.slurm.job_name << "\n"
     << "#SBATCH --array=1-" << tasks << "\n"
     << "#SBATCH --requeue\n"
     << "#SBATCH --cpus-per-task=" << spec.threads << "\n"
     << "#SBATCH --output=" << d << "/slurm/%A_%a.out\n";
  if (!spec.slurm.partition.empty()) sb << "#SBATCH --partition=" << spec.slurm.partition << "\n";
  if (!spec.slurm.time_limit.empty()) sb << "#SBATCH --time=" << spec.slurm.time_limit << "\n";
  if (!spec.slurm.memory.empty()) sb << "#SBATCH --mem=" << spec.slurm.memory << "\n";
  sb << "jobs=" << ShellQuote(d + "/jobs.txt") << "\n"
     << "status=0\n"
     << "for n in $(seq \"$SLURM_ARRAY_TASK_ID\" " << tasks << " " << jobs.size() << "); do\n"
     << "  line=$(sed -n \"${n}p\" \"$jobs\")\n"
     << "  if [ -z \"$line\" ]; then echo \"no line $n in $jobs\" >&2; exit 2; fi\n"
     << "  bash -c \"$line\" || status=1\n"
     << "done\n"
     << "[ -n \"${n:-}\" ] || { echo \"task $SLURM_ARRAY_TASK_ID: no line of $jobs is its\" >&2; exit 2; }\n"
     << "[ $status = 0 ] && exit 0\n"
     << "if [ \"${SLURM_RESTART_COUNT:-0}\" -lt " << spec.retries << " ]; then\n"
     << "  echo \"task ${SLURM_ARRAY_TASK_ID}: a job failed (attempt $(( ${SLURM_RESTART_COUNT:-0} + 1 ))); requeued\" "
        ">&2\n"
     << "  scontrol requeue \"${SLURM_ARRAY_JOB_ID}_${SLURM_ARRAY_TASK_ID}\" && sleep 300\n"
     << "fi\n"
     << "exit 1\n";
  WriteText(d + "/jobs.txt", txt.str());
  WriteText(d + "/jobs.tsv", tsv.str());
  WriteText(d + "/sweep.sbatch", sb.str());
  WriteText(d + "/sweep.json", manifest.dump(2) + "\n");
}

}  // namespace mbot::sweep
