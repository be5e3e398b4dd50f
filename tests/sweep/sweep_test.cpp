// libs/sweep: a [sweep] config expanded to jobs, the job line's protocol run by a real bash (a
// complete job skipped, a failed one recorded), and the merge of the jobs' outputs into one table.
// The engines themselves (GNU parallel, Slurm) are in tests/sweep/sweep_engines.sh.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "mbot/common/config.hpp"
#include "mbot/sweep/merge.hpp"
#include "mbot/sweep/sweep.hpp"

namespace mbot::sweep {
namespace {

namespace fs = std::filesystem;

std::string Slurp(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void Write(const std::string& path, const std::string& text) {
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream(path) << text;
}

// Runs `command` with bash; returns its exit status and puts its stdout in `out`.
int Bash(const std::string& command, std::string* out = nullptr) {
  // One script file per process: ctest runs each test in a process of its own, two at a time.
  const std::string script = ::testing::TempDir() + "/sweep_test_command_" + std::to_string(getpid()) + ".sh";
  Write(script, command + "\n");
  FILE* p = popen(("bash " + script + " 2>&1").c_str(), "r");
  std::string text;
  char buf[4096];
  while (size_t n = fread(buf, 1, sizeof buf, p)) text.append(buf, n);
  const int status = pclose(p);
  if (out) *out = text;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

class SweepTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir() + "/sweep_test_" +
                    ::testing::UnitTest::GetInstance()->current_test_info()->name())
               .lexically_normal()
               .string();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    Write(dir_ + "/base.ini", "[pipeline]\nstages =\n");
    Write(dir_ + "/other.ini", "[pipeline]\nstages =\n");
    Write(dir_ + "/generate.ini", "[pipeline]\nstages =\n");
    // A stand-in for mbot_nav: writes score.json (points.total = its seed) into output.dir, or
    // fails with a last log line when the file `fail` is beside it.
    Write(dir_ + "/fake_nav",
          "#!/bin/bash\nout=; seed=0\nwhile [ $# -gt 0 ]; do\n  if [ \"$1\" = --set ]; then\n    case \"$2\" in\n"
          "      output.dir=*) out=${2#output.dir=} ;;\n      pipeline.seed=*) seed=${2#pipeline.seed=} ;;\n"
          "    esac\n    shift\n  fi\n  shift\ndone\necho \"running seed $seed\"\n"
          "if [ -f \"$(dirname \"$0\")/fail\" ]; then echo \"boom: seed $seed\"; exit 3; fi\nmkdir -p \"$out\"\n"
          "printf '{\"completed\": true, \"points\": {\"total\": %s}, \"time_s\": %s.5}\\n' \"$seed\" \"$seed\" > "
          "\"$out/score.json\"\n");
    fs::permissions(dir_ + "/fake_nav", fs::perms::owner_all);
  }

  SweepSpec Parse(const std::string& ini) {
    Write(dir_ + "/sweep.ini", ini);
    return ParseSweep(config::Config::Load(dir_ + "/sweep.ini"), dir_ + "/fake_nav", dir_);
  }

  std::string dir_;
};

TEST(SweepRanges, NumbersAndRangesInOrder) {
  EXPECT_EQ(ParseRanges("1-3, 7,9-9"), (std::vector<uint64_t>{1, 2, 3, 7, 9}));
  EXPECT_EQ(ParseRanges("42"), (std::vector<uint64_t>{42}));
  for (const char* bad : {"", "3-1", "a", "1-x", "-4", "1-200000", "99999999999999999999"}) {
    EXPECT_THROW(ParseRanges(bad), std::invalid_argument) << bad;
  }
}

TEST(SweepShellQuote, BashReadsBackEveryWord) {
  for (const std::string word : {"plain", "a b", "it's", "$HOME", "${datasets}/x.map", "x; rm -rf /", "-0.9, -0.6, 45",
                                 "\"q\"", "back\\slash", "tab\there", ""}) {
    std::string out;
    ASSERT_EQ(Bash("printf '%s|' " + ShellQuote(word), &out), 0);
    EXPECT_EQ(out, word + "|") << ShellQuote(word);
  }
}

TEST_F(SweepTest, EveryCombinationTheLastAxisFastest) {
  const SweepSpec spec = Parse(
      "[sweep]\nconfig = ${config_dir}/base.ini\ncases = speed\ngrid = slam.particles=200,300\nseeds = 1-2\n"
      "set = mission.x=1; referee.y=2\n"
      "[speed]\nfast = config=${config_dir}/other.ini; mission.max_speed_m_s=0.5\nslow = mission.max_speed_m_s=0.2\n"
      "[output]\ndir = out\n");
  ASSERT_EQ(spec.axes.size(), 3u);
  EXPECT_EQ(spec.axes[0].name, "speed");
  EXPECT_EQ(spec.axes[1].name, "slam.particles");
  EXPECT_EQ(spec.axes[2].name, "seed");
  EXPECT_EQ(spec.output_dir, dir_ + "/out");
  const std::vector<Job> jobs = ExpandJobs(spec);
  ASSERT_EQ(jobs.size(), 8u);
  EXPECT_EQ(jobs[0].id, "speed-fast_slam.particles-200_seed-1");
  EXPECT_EQ(jobs[1].id, "speed-fast_slam.particles-200_seed-2");
  EXPECT_EQ(jobs[2].id, "speed-fast_slam.particles-300_seed-1");
  EXPECT_EQ(jobs[7].id, "speed-slow_slam.particles-300_seed-2");
  EXPECT_EQ(jobs[7].dir, dir_ + "/out/jobs/speed-slow_slam.particles-300_seed-2");
  ASSERT_EQ(jobs[0].runs.size(), 1u);
  // The case's config replaces the base; overrides in order: every job's, then each axis's.
  EXPECT_EQ(jobs[0].runs[0],
            (std::vector<std::string>{dir_ + "/fake_nav", "--quiet", "--config", dir_ + "/other.ini", "--set",
                                      "mission.x=1", "--set", "referee.y=2", "--set", "mission.max_speed_m_s=0.5",
                                      "--set", "slam.particles=200", "--set", "pipeline.seed=1", "--set",
                                      "pipeline.progress=off", "--set", "output.dir=" + jobs[0].dir}));
  EXPECT_EQ(jobs[7].runs[0][3], dir_ + "/base.ini");
}

TEST_F(SweepTest, AGeneratedMazeIsMadeByTheJobItself) {
  const SweepSpec spec = Parse(
      "[sweep]\nconfig = ${config_dir}/base.ini\nmaze_config = ${config_dir}/generate.ini\n"
      "mazes = 4, 9\n[output]\ndir = out\n");
  const std::vector<Job> jobs = ExpandJobs(spec);
  ASSERT_EQ(jobs.size(), 2u);
  EXPECT_EQ(jobs[1].id, "maze-9");
  ASSERT_EQ(jobs[1].runs.size(), 2u);
  EXPECT_EQ(jobs[1].runs[0][3], dir_ + "/generate.ini");
  EXPECT_EQ(jobs[1].runs[0][5], "mazes.first_seed=9");
  EXPECT_EQ(jobs[1].runs[1][5], "source.path=" + jobs[1].dir + "/world/maze_9.arena");
}

TEST_F(SweepTest, MistakesNameTheKey) {
  const std::string head = "[sweep]\nconfig = ${config_dir}/base.ini\n";
  auto error = [&](const std::string& ini) {
    try {
      Parse(ini);
    } catch (const config::ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error(head + "seed = 1\n").find("seed"), std::string::npos);  // unknown key
  EXPECT_NE(error(head + "seeds = 1, 1\n").find("appears twice"), std::string::npos);
  EXPECT_NE(error(head + "seeds = 3-1\n").find("backwards"), std::string::npos);
  EXPECT_NE(error(head + "grid = particles=1,2\n").find("not section.key=value"), std::string::npos);
  EXPECT_NE(error(head + "mazes = 1\nworlds = base.ini\n").find("give one"), std::string::npos);
  EXPECT_NE(error(head + "cases = nope\n").find("no [nope] section"), std::string::npos);
  EXPECT_NE(error(head + "[stray]\nx = 1\n").find("[stray] is not used"), std::string::npos);
  EXPECT_NE(error(head + "metrics = metrics.ate\n").find("metrics"), std::string::npos);
  EXPECT_NE(error("[sweep]\nconfig = ${config_dir}/missing.ini\n").find("no such file"), std::string::npos);
  EXPECT_NE(error(head + "cases = c\n[c]\nbad/name = a.b=1\n").find("bad/name"), std::string::npos);
  EXPECT_NE(error(head + "slurm_time = 1 hour\n").find("slurm_time"), std::string::npos);
  EXPECT_NE(error(head + "maze_config = ${config_dir}/generate.ini\nmazes = 3000000000\n").find("2147483647"),
            std::string::npos);
  EXPECT_NE(error(head + "[output]\ndir = a%b\n").find("[output] dir"), std::string::npos);
}

TEST_F(SweepTest, ValueNamesThatRunIntoEachOtherAreRefused) {
  const SweepSpec spec = Parse("[sweep]\nconfig = ${config_dir}/base.ini\ngrid = a.x=1_a.y-2,1; a.y=3,2_a.y-3\n");
  try {
    ExpandJobs(spec);
    ADD_FAILURE() << "two jobs of one id";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("are both called a.x-1_a.y-2_a.y-3"), std::string::npos) << e.what();
  }
}

TEST_F(SweepTest, TheLineSkipsACompleteJobAndRecordsAFailedOne) {
  const SweepSpec spec = Parse("[sweep]\nconfig = ${config_dir}/base.ini\nseeds = 5\n[output]\ndir = out\n");
  const Job job = ExpandJobs(spec).at(0);
  std::string out;
  EXPECT_EQ(Bash(job.command, &out), 0);
  EXPECT_EQ(Slurp(job.dir + "/exit_status").substr(0, 2), "0 ");
  EXPECT_NE(Slurp(job.dir + "/job.log").find("running seed 5"), std::string::npos);
  EXPECT_EQ(Bash(job.command, &out), 0);
  EXPECT_EQ(out, "seed-5: complete, skipped\n");
  fs::remove(job.dir + "/score.json");  // outputs incomplete: runs again, and fails this time
  Write(dir_ + "/fail", "");
  EXPECT_EQ(Bash(job.command, &out), 1);
  EXPECT_EQ(Slurp(job.dir + "/exit_status").substr(0, 2), "3 ");
  EXPECT_NE(Slurp(job.dir + "/job.log").find("boom"), std::string::npos);
  fs::remove(dir_ + "/fail");
  EXPECT_EQ(Bash(job.command, &out), 0);  // a failed job is not "complete"
  EXPECT_TRUE(fs::exists(job.dir + "/score.json"));
  EXPECT_EQ(Bash(job.command, &out), 0);
  EXPECT_EQ(out, "seed-5: complete, skipped\n");
  // An edited base config makes the recorded result another command's: the job runs again.
  Write(dir_ + "/base.ini", "[pipeline]\nstages = edited\n");
  const Job edited = ExpandJobs(spec).at(0);
  EXPECT_NE(edited.command, job.command);
  EXPECT_EQ(Bash(edited.command, &out), 0);
  EXPECT_EQ(out, "") << out;
}

TEST_F(SweepTest, WritesTheListTheArrayAndTheManifest) {
  const SweepSpec spec = Parse(
      "[sweep]\nconfig = ${config_dir}/base.ini\nseeds = 1-3\nretries = 4\n"
      "slurm_time = 00:10:00\nthreads = 2\n[output]\ndir = out\n");
  const std::vector<Job> jobs = ExpandJobs(spec);
  WriteSweep(spec, jobs);
  std::istringstream lines(Slurp(spec.output_dir + "/jobs.txt"));
  int n = 0;
  for (std::string l; std::getline(lines, l); ++n) EXPECT_EQ(l, jobs[n].command);
  EXPECT_EQ(n, 3);
  const std::string sbatch = Slurp(spec.output_dir + "/sweep.sbatch");
  EXPECT_NE(sbatch.find("#SBATCH --array=1-3\n"), std::string::npos);
  EXPECT_NE(sbatch.find("#SBATCH --requeue\n"), std::string::npos);
  EXPECT_NE(sbatch.find("#SBATCH --time=00:10:00\n"), std::string::npos);
  EXPECT_NE(sbatch.find("-lt 4 ]"), std::string::npos);
  EXPECT_NE(sbatch.find("#SBATCH --cpus-per-task=2\n"), std::string::npos);
  EXPECT_NE(jobs[0].command.find(" && export OMP_NUM_THREADS=2 && "), std::string::npos);
  EXPECT_TRUE(fs::is_directory(spec.output_dir + "/slurm"));
  EXPECT_TRUE(IsSweepFolder(spec.output_dir));
  EXPECT_NE(Slurp(spec.output_dir + "/jobs.tsv").find("id\tdir\tseed\tcommand\n"), std::string::npos);
}

TEST_F(SweepTest, AnArrayTaskRunsItsLinesAndOnlyThose) {
  const SweepSpec spec = Parse(
      "[sweep]\nconfig = ${config_dir}/base.ini\nseeds = 1-3\nslurm_lines_per_task = 2\n"
      "[output]\ndir = out\n");
  const std::vector<Job> jobs = ExpandJobs(spec);
  WriteSweep(spec, jobs);
  const std::string sbatch = spec.output_dir + "/sweep.sbatch";
  EXPECT_NE(Slurp(sbatch).find("#SBATCH --array=1-2\n"), std::string::npos);
  std::string out;
  ASSERT_EQ(Bash("SLURM_ARRAY_TASK_ID=2 bash " + sbatch, &out), 0) << out;  // line 2 only
  EXPECT_FALSE(fs::exists(jobs[0].dir + "/score.json"));
  EXPECT_TRUE(fs::exists(jobs[1].dir + "/score.json"));
  EXPECT_FALSE(fs::exists(jobs[2].dir + "/score.json"));
  ASSERT_EQ(Bash("SLURM_ARRAY_TASK_ID=1 bash " + sbatch, &out), 0) << out;  // lines 1 and 3
  EXPECT_TRUE(fs::exists(jobs[0].dir + "/score.json"));
  EXPECT_TRUE(fs::exists(jobs[2].dir + "/score.json"));
  EXPECT_EQ(Bash("SLURM_ARRAY_TASK_ID=4 bash " + sbatch, &out), 2);  // past the end: said, not run
  EXPECT_NE(out.find("no line of"), std::string::npos) << out;
}

TEST_F(SweepTest, MergeGivesMedianMinMaxAndNamesFailures) {
  const SweepSpec spec = Parse(
      "[sweep]\nconfig = ${config_dir}/base.ini\ncases = arm\nseeds = 1-4\n"
      "metrics = score.points.total, score.completed\n[arm]\na = x.y=1\nb = x.y=2\n"
      "[output]\ndir = out\n");
  const std::vector<Job> jobs = ExpandJobs(spec);
  WriteSweep(spec, jobs);
  ASSERT_EQ(jobs.size(), 8u);
  for (size_t k = 0; k < 6; ++k) ASSERT_EQ(Bash(jobs[k].command), 0) << jobs[k].id;
  Write(dir_ + "/fail", "");
  EXPECT_EQ(Bash(jobs[6].command), 1);  // arm-b_seed-3 fails; arm-b_seed-4 never runs
  const MergeSummary m = MergeSweep(spec.output_dir, spec.output_dir);
  EXPECT_EQ(m.jobs, 8);
  EXPECT_EQ(m.failed, 1);
  EXPECT_EQ(m.not_run, 1);
  const std::string md = Slurp(spec.output_dir + "/sweep.md");
  EXPECT_NE(md.find("| all |  | 8 | 2 | 2 [1, 4] | 6/6 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| arm | a | 4 | 0 | 2.5 [1, 4] | 4/4 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| arm | b | 4 | 2 | 1.5 [1, 2] | 2/2 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| seed | 3 | 2 | 1 | 3 | 1/1 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| arm-b_seed-3 | failed | exit status 3 | boom: seed 3 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| arm-b_seed-4 | not run | no exit status |"), std::string::npos) << md;
  const std::string csv = Slurp(spec.output_dir + "/sweep.csv");
  EXPECT_EQ(csv.rfind("id,arm,seed,status,why,score.completed,score.points.total,score.time_s\n", 0), 0u) << csv;
  EXPECT_NE(csv.find("arm-a_seed-2,a,2,ok,,1,2,2.5\n"), std::string::npos) << csv;
  EXPECT_TRUE(fs::exists(spec.output_dir + "/plots/score.points.total.png"));

  // A corrupt output is that job's failure, named with the file and offset; the rest still merge.
  Write(jobs[0].dir + "/score.json", "{\"points\": {\"total\": 1,");
  MergeSweep(spec.output_dir, spec.output_dir);
  const std::string md2 = Slurp(spec.output_dir + "/sweep.md");
  EXPECT_NE(md2.find("| arm-a_seed-1 | failed | " + jobs[0].dir + "/score.json: not JSON (at byte"), std::string::npos)
      << md2;
  EXPECT_NE(md2.find("| arm | a | 4 | 1 | 3 [2, 4] | 3/3 |"), std::string::npos) << md2;
}

}  // namespace
}  // namespace mbot::sweep
