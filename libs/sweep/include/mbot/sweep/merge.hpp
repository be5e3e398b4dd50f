// The end of a sweep: every job's JSON outputs (score.json, metrics.json) into one CSV and one
// Markdown table — per axis value the median, min and max of each metric and the failures — with a
// PNG plot per metric, and every failed job named with the last line of its log.
#pragma once

#include <string>
#include <vector>

namespace mbot::sweep {

struct MergeSummary {
  int jobs = 0;
  int failed = 0;                    // ran and exited non-zero, or left an output missing
  int not_run = 0;                   // no exit status recorded (never started, or killed before it ended)
  std::vector<std::string> written;  // the files written, absolute
};

// Reads `dir`/sweep.json (WriteSweep's manifest) and each job's folder; writes `into`/sweep.csv,
// sweep.md and plots/<metric>.png. sweep.md depends on the jobs' outputs alone (not on the engine,
// the order the jobs ran in or their wall time), so one sweep gives one table however it was run.
// Throws std::runtime_error naming the file (and the JSON offset) that cannot be read.
MergeSummary MergeSweep(const std::string& dir, const std::string& into);

// True when `dir` holds a sweep's manifest (for source detection).
bool IsSweepFolder(const std::string& dir);

}  // namespace mbot::sweep
