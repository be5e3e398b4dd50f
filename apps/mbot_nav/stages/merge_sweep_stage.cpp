// `merge_sweep`: the table at the end of a sweep (libs/sweep MergeSweep): the source is the sweep
// folder ([source] type = sweep); sweep.csv, sweep.md and plots/ are written into it (or `into`).
#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/sweep/merge.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

class MergeSweepStage : public Stage {
 public:
  explicit MergeSweepStage(std::string into) : into_(std::move(into)) {}
  void OnEvent(const msgs::Event&) override {}

  void Finish(const RunContext& ctx, bool /*interrupted*/) override {
    const std::string into = into_.empty() ? ctx.source_path : into_;
    const sweep::MergeSummary m = sweep::MergeSweep(ctx.source_path, into);
    mbot::log::Info("merge_sweep: " + std::to_string(m.jobs) + " jobs, " + std::to_string(m.failed) + " failed, " +
                    std::to_string(m.not_run) + " not run; wrote " + into + "/sweep.csv, sweep.md and " +
                    std::to_string(m.written.size() - 2) + " plots");
    if (m.failed + m.not_run > 0) {
      mbot::log::Warn("merge_sweep: " + std::to_string(m.failed + m.not_run) +
                      " jobs failed or did not run; sweep.md names them with their last log line");
    }
  }

 private:
  std::string into_;
};

}  // namespace

static StageType MergeSweepStageType() {
  return {"merge_sweep",
          "merges a sweep folder's job outputs (score.json, metrics.json) into sweep.csv, sweep.md (per axis value: "
          "median, min, max, failures) and a PNG plot per metric",
          [](config::Section& s) -> std::unique_ptr<Stage> {
            return std::make_unique<MergeSweepStage>(
                s.GetPath("into", "", "folder for sweep.csv, sweep.md and plots/ ('' = the sweep folder itself)"));
          }};
}

const RegisterStage kMergeSweepRegistered{MergeSweepStageType()};

}  // namespace mbot::app
