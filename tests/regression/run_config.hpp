// Shared by the regression tests: run a shipped config with overrides into a fresh folder under
// the test temp dir and read numbers back out of the JSON report it wrote.
#pragma once

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "mbot/common/config.hpp"
#include "mbot/pipeline/pipeline.hpp"

namespace mbot::app {

// The text of a report a run wrote ("" when it was not written).
inline std::string ReadReport(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Runs config/<config_name> with `sets` (section.key=value, or "--unset section.key") into TempDir()/<out_name>;
// returns the text of <report> in that folder ("" when it was not written).
inline std::string RunConfig(const std::string& config_name, const std::string& out_name,
                             const std::vector<std::string>& sets, const std::string& report) {
  auto c = config::Config::Load(std::string(MBOT_SOURCE_DIR) + "/config/" + config_name);
  const std::string out = ::testing::TempDir() + "/" + out_name;
  std::filesystem::remove_all(out);
  c.Set("output.dir=" + out);
  c.Set("pipeline.progress=off");
  for (const auto& s : sets) s.rfind("--unset ", 0) == 0 ? c.Unset(s.substr(8)) : c.Set(s);
  auto plan = pipeline::BuildPlan(c);
  std::atomic<bool> stop{false};
  pipeline::RunPlan(plan, stop);
  return ReadReport(out + "/" + report);
}

// The number after the keys, found one after another in the JSON text (e.g. "slam_ate",
// "aligned", "x_m", "rmse").
inline double Get(const std::string& json, const std::vector<std::string>& keys) {
  size_t pos = 0;
  for (const auto& k : keys) {
    pos = json.find("\"" + k + "\"", pos);
    if (pos == std::string::npos) ADD_FAILURE() << "no key " << k;
    if (pos == std::string::npos) return NAN;
    pos += k.size() + 2;
  }
  pos = json.find(':', pos);
  return std::stod(json.substr(pos + 1));
}

// A TUM trajectory's positions by stamp (the stamp as written, so two runs' files pair exactly).
inline std::map<std::string, std::pair<double, double>> TumXy(const std::string& path) {
  std::map<std::string, std::pair<double, double>> out;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    std::string t;
    double x, y;
    if (s >> t >> x >> y) out[t] = {x, y};
  }
  return out;
}

// The Maze Explorer's bounds on a referee's score.json: completed, no collision, >= 99 % of the
// reachable free space mapped, mapped walls where true walls are, home within 0.05 m.
inline void ExpectExploredMappedAndHome(const std::string& j) {
  ASSERT_FALSE(j.empty());
  EXPECT_NE(j.find("\"completed\": true"), std::string::npos) << j;
  EXPECT_EQ(Get(j, {"collisions"}), 0);
  EXPECT_GE(Get(j, {"map", "coverage"}), 0.99);
  EXPECT_GE(Get(j, {"map", "wall_precision"}), 0.95);
  EXPECT_LE(std::hypot(Get(j, {"final_error", "x_m"}), Get(j, {"final_error", "y_m"})), 0.05);
  for (const char* k : {"time_s", "real_time_factor"}) ::testing::Test::RecordProperty(k, std::to_string(Get(j, {k})));
}

}  // namespace mbot::app
