#include "mbot/sweep/merge.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/files.hpp"
#include "mbot/common/strings.hpp"
#include "mbot/drivers/plot.hpp"

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

namespace mbot::sweep {
namespace {

// One leaf of a job's outputs: a number (bools as 0/1, `boolean` set) or a string.
struct Value {
  double number = NAN;
  std::string text;
  bool is_number = false, boolean = false;
};

struct JobResult {
  std::string id, dir;
  std::vector<std::string> axis_values;  // in the manifest's axis order
  std::string status = "ok";             // ok, failed, not run
  std::string why;                       // for failed / not run: exit status, the missing output
  std::string last_log_line;
  std::map<std::string, Value> values;  // "<stem>.<path>" -> leaf
};

// What the merge reads: the manifest (WriteSweep's sweep.json) and each job's results.
struct SweepResults {
  std::string name;
  std::vector<std::string> axes, outputs, metrics;
  std::vector<std::vector<std::string>> axis_values;  // per axis, in the manifest's order
  std::vector<JobResult> jobs;
  std::vector<std::string> columns;  // every leaf of any job's outputs, in first-seen order
};

std::string ReadFile(const std::string& path) {
  RequireReadableFile(path);
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

json ReadJson(const std::string& path) {
  try {
    return json::parse(ReadFile(path));
  } catch (const json::parse_error& e) {
    throw std::runtime_error(path + ": not JSON (at byte " + std::to_string(e.byte) + ")");
  }
}

// Leaves of `j` under `prefix`; arrays of up to 64 items by index (longer ones are data, not results).
void Flatten(const json& j, const std::string& prefix, std::vector<std::string>* order,
             std::map<std::string, Value>* out) {
  auto put = [&](Value v) {
    if (out->emplace(prefix, v).second) order->push_back(prefix);
  };
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) Flatten(it.value(), prefix + "." + it.key(), order, out);
  } else if (j.is_array()) {
    if (j.size() > 64) return;
    for (size_t i = 0; i < j.size(); ++i) Flatten(j[i], prefix + "." + std::to_string(i), order, out);
  } else if (j.is_boolean()) {
    put({j.get<bool>() ? 1.0 : 0.0, "", true, true});
  } else if (j.is_number()) {
    put({j.get<double>(), "", true, false});
  } else if (j.is_string()) {
    put({NAN, j.get<std::string>(), false, false});
  }
}

// The job's value of `metric` when it is a finite number (or a yes/no), else nullptr.
const Value* NumberOf(const JobResult& job, const std::string& metric) {
  auto it = job.values.find(metric);
  if (it == job.values.end() || !it->second.is_number || !std::isfinite(it->second.number)) return nullptr;
  return &it->second;
}

std::string LastLogLine(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "(no job.log)";
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  const std::streamoff from = std::max<std::streamoff>(0, size - 65536);
  in.seekg(from);
  std::string tail(static_cast<size_t>(size - from), '\0');
  in.read(tail.data(), static_cast<std::streamsize>(tail.size()));
  std::string last;
  std::istringstream lines(tail);
  for (std::string l; std::getline(lines, l);) {
    if (!Trim(l).empty()) last = Trim(l);
  }
  if (last.size() > 200) last = last.substr(0, 197) + "...";
  return last.empty() ? "(empty job.log)" : last;
}

std::string Csv(const std::string& field) {
  if (field.find_first_of(",\"\n\r") == std::string::npos) return field;
  std::string out = "\"";
  for (char c : field) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string Md(std::string s) {
  for (size_t p = 0; (p = s.find('|', p)) != std::string::npos; p += 2) s.replace(p, 1, "\\|");
  return s;
}

std::string Number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// "median [min, max]" of the metric over `jobs` (one number when they are all the same), or "k/n"
// for a yes/no metric; "–" without values.
std::string Cell(const std::vector<const JobResult*>& jobs, const std::string& metric) {
  std::vector<double> v;
  bool boolean = true;
  for (const JobResult* j : jobs) {
    if (const Value* x = NumberOf(*j, metric)) {
      v.push_back(x->number);
      boolean = boolean && x->boolean;
    }
  }
  if (v.empty()) return "–";
  if (boolean) {
    const auto yes = std::count(v.begin(), v.end(), 1.0);
    return std::to_string(yes) + "/" + std::to_string(v.size());
  }
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  if (*lo == *hi) return Number(*lo);
  return Number(Median(v)) + " [" + Number(*lo) + ", " + Number(*hi) + "]";
}

std::string PlotName(const std::string& metric) {
  std::string out;
  for (char c : metric) out += std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-' ? c : '_';
  return out + ".png";
}

SweepResults ReadManifest(const std::string& dir) {
  const std::string path = (fs::path(dir) / "sweep.json").string();
  const json manifest = ReadJson(path);
  SweepResults r;
  try {
    r.name = manifest.value("name", std::string("?"));
    for (const json& a : manifest.at("axes")) {
      r.axes.push_back(a.at("name").get<std::string>());
      r.axis_values.push_back(a.at("values").get<std::vector<std::string>>());
    }
    r.outputs = manifest.at("outputs").get<std::vector<std::string>>();
    r.metrics = manifest.at("metrics").get<std::vector<std::string>>();
    for (const json& j : manifest.at("jobs")) {
      JobResult job;
      job.id = j.at("id").get<std::string>();
      job.dir = j.at("dir").get<std::string>();
      for (const std::string& a : r.axes) job.axis_values.push_back(j.at("axes").at(a).get<std::string>());
      r.jobs.push_back(std::move(job));
    }
  } catch (const json::exception& e) {
    throw std::runtime_error(path + ": not a sweep manifest (" + e.what() + ")");
  }
  return r;
}

// Each job's status (exit_status) and, when it ended well, the leaves of its outputs.
void ReadJobs(const std::string& dir, SweepResults* sweep, MergeSummary* summary) {
  std::set<std::string> seen;
  for (JobResult& r : sweep->jobs) {
    // The jobs' folders move with the sweep folder: one that is not where the manifest says is
    // looked for under dir/jobs/<id>.
    if (!fs::is_directory(r.dir)) r.dir = (fs::path(dir) / "jobs" / r.id).string();
    std::ifstream status_file(r.dir + "/exit_status");
    std::string status;
    if (!(status_file >> status)) {
      r.status = "not run", r.why = "no exit status";
    } else if (status != "0") {
      r.status = "failed", r.why = "exit status " + status;
    }
    for (const std::string& o : sweep->outputs) {
      if (r.status != "ok") break;
      const std::string path = r.dir + "/" + o;
      if (!fs::is_regular_file(path)) {
        r.status = "failed", r.why = o + " missing";
        break;
      }
      try {
        std::vector<std::string> order;
        Flatten(ReadJson(path), o.substr(0, o.size() - 5), &order, &r.values);
        for (const std::string& c : order) {
          if (seen.insert(c).second) sweep->columns.push_back(c);
        }
      } catch (const std::runtime_error& e) {
        r.status = "failed", r.why = e.what();
      }
    }
    if (r.status != "ok") {
      r.values.clear();
      r.last_log_line = LastLogLine(r.dir + "/job.log");
      (r.status == "failed" ? summary->failed : summary->not_run)++;
    }
  }
  if (sweep->metrics.empty()) {  // every number of the results but the wall-clock ones
    for (const std::string& c : sweep->columns) {
      for (const JobResult& r : sweep->jobs) {
        if (auto it = r.values.find(c); it != r.values.end()) {
          // Wall-clock figures would make the table depend on the machine and the engine.
          const bool wall = c.find("wall") != std::string::npos || c.find("real_time_factor") != std::string::npos;
          if (it->second.is_number && !wall) sweep->metrics.push_back(c);
          break;
        }
      }
    }
  }
}

std::string CsvText(const SweepResults& sweep) {
  std::ostringstream csv;
  csv << "id";
  for (const std::string& a : sweep.axes) csv << "," << Csv(a);
  csv << ",status,why";
  for (const std::string& c : sweep.columns) csv << "," << Csv(c);
  csv << "\n";
  for (const JobResult& r : sweep.jobs) {
    csv << Csv(r.id);
    for (const std::string& v : r.axis_values) csv << "," << Csv(v);
    csv << "," << Csv(r.status) << "," << Csv(r.why);
    for (const std::string& c : sweep.columns) {
      csv << ",";
      auto it = r.values.find(c);
      if (it == r.values.end()) continue;
      csv << Csv(it->second.is_number ? Significant(it->second.number, 10) : it->second.text);
    }
    csv << "\n";
  }
  return csv.str();
}

std::string MarkdownText(const SweepResults& sweep, const MergeSummary& summary) {
  std::ostringstream md;
  md << "# Sweep " << sweep.name << ": " << sweep.jobs.size() << " jobs, " << summary.failed << " failed, "
     << summary.not_run << " not run\n\n"
     << "Each cell: median [min, max] over the jobs that completed (yes/no metrics: how many of them).\n\n";
  md << "| axis | value | jobs | failed or not run |";
  for (const std::string& m : sweep.metrics) md << " " << Md(m) << " |";
  md << "\n|---|---|---|---|";
  for (size_t k = 0; k < sweep.metrics.size(); ++k) md << "---|";
  md << "\n";
  // One row per group: the whole sweep, then each value of each axis.
  auto row = [&](const std::string& axis, const std::string& value, int a) {
    size_t jobs = 0;
    std::vector<const JobResult*> ok;
    for (const JobResult& r : sweep.jobs) {
      if (a >= 0 && r.axis_values[a] != value) continue;
      ++jobs;
      if (r.status == "ok") ok.push_back(&r);
    }
    md << "| " << Md(axis) << " | " << Md(value) << " | " << jobs << " | " << jobs - ok.size() << " |";
    for (const std::string& m : sweep.metrics) md << " " << Cell(ok, m) << " |";
    md << "\n";
  };
  row("all", "", -1);
  for (size_t a = 0; a < sweep.axes.size(); ++a) {
    for (const std::string& value : sweep.axis_values[a]) row(sweep.axes[a], value, static_cast<int>(a));
  }
  if (summary.failed + summary.not_run > 0) {
    md << "\n## Jobs that failed or did not run\n\n| job | status | why | last log line |\n|---|---|---|---|\n";
    for (const JobResult& r : sweep.jobs) {
      if (r.status != "ok")
        md << "| " << Md(r.id) << " | " << r.status << " | " << Md(r.why) << " | " << Md(r.last_log_line) << " |\n";
    }
  }
  return md.str();
}

// A plot per metric against the first axis (numbers where its values are numbers, else their
// position; without axes, the job's position), every job a dot and the median a line. The last
// merge's plots go first: a metric may be gone.
void WritePlots(const SweepResults& sweep, const std::string& folder, MergeSummary* summary) {
  std::error_code ec;
  fs::remove_all(folder, ec);
  const bool by_axis = !sweep.axes.empty();
  std::vector<double> x_of;  // x of each value of the first axis
  if (by_axis) {
    bool numeric = true;
    for (const std::string& v : sweep.axis_values[0]) {
      char* end = nullptr;
      const double d = std::strtod(v.c_str(), &end);
      numeric = numeric && end && *end == '\0' && std::isfinite(d);
      x_of.push_back(d);
    }
    if (!numeric) {
      for (size_t i = 0; i < x_of.size(); ++i) x_of[i] = static_cast<double>(i + 1);
    }
  }
  for (const std::string& m : sweep.metrics) {
    drivers::PlotSeries dots, median;
    dots.points = true, dots.b = 200, dots.label = "job";
    median.r = 220, median.label = "median";
    for (size_t i = 0; i < (by_axis ? sweep.axis_values[0].size() : size_t{1}); ++i) {
      std::vector<double> ys;
      for (size_t k = 0; k < sweep.jobs.size(); ++k) {
        const JobResult& r = sweep.jobs[k];
        if (by_axis && r.axis_values[0] != sweep.axis_values[0][i]) continue;
        if (const Value* v = NumberOf(r, m)) {
          dots.x.push_back(by_axis ? x_of[i] : static_cast<double>(k + 1)), dots.y.push_back(v->number);
          ys.push_back(v->number);
        }
      }
      if (!ys.empty() && by_axis) median.x.push_back(x_of[i]), median.y.push_back(Median(ys));
    }
    if (dots.x.empty()) continue;
    drivers::PlotOptions po;
    po.title = m + (by_axis ? " by " + sweep.axes[0] : "");
    po.x_label = by_axis ? sweep.axes[0] : "job";
    po.y_label = m;
    EnsureDirectory(folder);
    const std::string path = folder + "/" + PlotName(m);
    drivers::WritePlotPng({dots, median}, po, path);
    summary->written.push_back(path);
  }
}

}  // namespace

bool IsSweepFolder(const std::string& dir) {
  std::error_code ec;
  return fs::is_directory(dir, ec) && fs::is_regular_file(fs::path(dir) / "sweep.json", ec);
}

MergeSummary MergeSweep(const std::string& dir, const std::string& into) {
  SweepResults sweep = ReadManifest(dir);
  MergeSummary summary;
  summary.jobs = static_cast<int>(sweep.jobs.size());
  ReadJobs(dir, &sweep, &summary);
  EnsureDirectory(into);
  WriteFileAtomically(into + "/sweep.csv", [&](std::ostream& f) { f << CsvText(sweep); });
  WriteFileAtomically(into + "/sweep.md", [&](std::ostream& f) { f << MarkdownText(sweep, summary); });
  summary.written = {into + "/sweep.csv", into + "/sweep.md"};
  WritePlots(sweep, into + "/plots", &summary);
  return summary;
}

}  // namespace mbot::sweep
