#include "competition.hpp"
#include "mbot/pipeline/pipeline.hpp"
#include "sweep_mode.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

namespace mbot::app {
namespace {

std::string ErrorOf(const std::string& ini) {
  try {
    pipeline::BuildPlan(config::Config::FromString(ini, "t.ini"));
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "";
}

constexpr const char* kBase = "[pipeline]\nstages = s\n[source]\npath = x.log\n";

TEST(PipelineTest, BuildsRegisteredStages) {
  auto plan = pipeline::BuildPlan(config::Config::FromString(std::string(kBase) + "[s]\ntype = inspect\n", "t.ini"));
  ASSERT_EQ(plan.stages.size(), 1u);
  EXPECT_EQ(plan.stages[0].first, "s");
  EXPECT_EQ(plan.source.path, "x.log");
}

TEST(PipelineTest, UnknownStageTypeListsTheKnownOnes) {
  const auto e = ErrorOf(std::string(kBase) + "[s]\ntype = nope\n");
  EXPECT_NE(
      e.find("t.ini:6: [s] type: unknown stage type 'nope' (known: action_model_fit, astar_test, camera_calibration, "
             "exploration, fit_sim_model, "
             "inspect, lcm_bridge, map_writer, maze_generator, merge_sweep, mission, motor_calibration, "
             "movingai_benchmark, "
             "odometry, "
             "referee, ros2_bridge, sim_fidelity, slam, tag_detection, tag_sightings, trajectory_writer)"),
      std::string::npos)
      << e;
}

// A key nothing would read is an error: a path for type = none, the channel roles for a type whose
// messages do not take their meaning from the channel.
TEST(PipelineTest, AKeyNothingReadsIsAnError) {
  EXPECT_NE(ErrorOf("[pipeline]\nstages = s\n[source]\ntype = none\npath = my_views/\n[s]\ntype = inspect\n")
                .find("[source] path: type = none reads no input"),
            std::string::npos);
  EXPECT_NE(ErrorOf("[pipeline]\nstages = s\n[source]\ntype = carmen\npath = x.log\nodometry_channels = A\n[s]\n"
                    "type = inspect\n")
                .find("[source] odometry_channels: unknown key"),
            std::string::npos);
  EXPECT_EQ(ErrorOf("[pipeline]\nstages = s\n[source]\ntype = lcm_log\npath = x.log\nodometry_channels = A\n[s]\n"
                    "type = inspect\n"),
            "");
}

TEST(PipelineTest, StrictErrors) {
  EXPECT_NE(ErrorOf(std::string(kBase) + "[s]\ntype = inspect\nbogus = 1\n").find("[s] bogus: unknown key"),
            std::string::npos);
  EXPECT_NE(ErrorOf(std::string(kBase)).find("stage 's' has no [s] section"), std::string::npos);
  EXPECT_NE(ErrorOf(std::string(kBase) + "[s]\ntype = inspect\n[extra]\nx = 1\n").find("[extra] is not used"),
            std::string::npos);
  EXPECT_NE(ErrorOf("[pipeline]\nstages = s\n[s]\ntype = inspect\n").find("[source] path: required key is missing"),
            std::string::npos);
  EXPECT_NE(
      ErrorOf(std::string(kBase) + "type = lcm\n[s]\ntype = inspect\n").find("[source] type: 'lcm' is not one of"),
      std::string::npos);
}

// A maze seed past an int would wrap (maze_18446744073709551615): refused, naming the key.
TEST(PipelineTest, MazeSeedsStayInts) {
  const std::string base = "[pipeline]\nstages = m\n[source]\ntype = none\n[m]\ntype = maze_generator\n";
  EXPECT_NE(ErrorOf(base + "first_seed = 9223372036854775000\n")
                .find("[m] first_seed: value 9223372036854775000 out of range"),
            std::string::npos);
  EXPECT_NE(
      ErrorOf(base + "first_seed = 2147483640\ncount = 10\n").find("[m] first_seed: first_seed + count - 1 passes"),
      std::string::npos);
  EXPECT_EQ(ErrorOf(base + "first_seed = 2147483638\ncount = 10\n"), "");
}

// Nothing passes silently: an input without a usable event fails the run, naming the file; a
// directory given as a log file is named as one.
TEST(PipelineTest, AnEmptyInputFailsTheRun) {
  const std::string empty = ::testing::TempDir() + "/empty.log";
  std::ofstream(empty).flush();
  auto c = config::Config::FromString(
      std::string("[pipeline]\nstages = s\nprogress = off\n[source]\ntype = carmen\npath = ") + empty +
      "\n[output]\ndir = " + ::testing::TempDir() + "/empty_out\n[s]\ntype = inspect\n");
  pipeline::PipelinePlan plan = pipeline::BuildPlan(c);
  const std::atomic<bool> stop{false};
  try {
    pipeline::RunPlan(plan, stop);
    ADD_FAILURE();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(empty + ": no usable event"), std::string::npos) << e.what();
  }
  c.Set("source.type=lcm_log");
  c.Set("source.path=" + ::testing::TempDir());
  pipeline::PipelinePlan dir_plan = pipeline::BuildPlan(c);
  EXPECT_THROW(pipeline::RunPlan(dir_plan, stop), std::runtime_error);
}

// Every shipped configuration parses strictly (keys, sections, stage types, values; a sweep's every
// job). A fragment
// (no [pipeline] and no [competition]: defaults.ini, warehouse_day.ini) is checked through the
// configs that include it, and must be included by one.
TEST(PipelineTest, EveryShippedConfigIsValid) {
  int n = 0;
  std::string all_text;
  std::vector<std::string> fragments;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(MBOT_SOURCE_DIR) + "/config")) {
    if (entry.path().extension() != ".ini") continue;
    SCOPED_TRACE(entry.path().string());
    std::ifstream in(entry.path());
    all_text += std::string(std::istreambuf_iterator<char>(in), {});
    const config::Config c = config::Config::Load(entry.path().string());
    if (sweep::IsSweep(c)) {  // every job's own configuration is built too
      EXPECT_NO_THROW(BuildSweep(c, "/bin/true"));
      ++n;
      continue;
    }
    if (entry.path().filename() == "defaults.ini" || (!c.HasSection("pipeline") && !IsCompetition(c))) {
      fragments.push_back(entry.path().filename().string());
      continue;
    }
    if (IsCompetition(c)) {
      EXPECT_NO_THROW(BuildCompetition(c));
    } else {
      EXPECT_NO_THROW(pipeline::BuildPlan(c));
    }
    ++n;
  }
  EXPECT_GE(n, 3);
  for (const std::string& f : fragments) {
    EXPECT_NE(all_text.find("include = " + f), std::string::npos) << f << " is a fragment no shipped config includes";
  }
}

}  // namespace
}  // namespace mbot::app
