// `inspect`: a summary of any dataset — channels, message generation, counts, mean rates, time
// span, beams per scan, ranges, ground truth — printed and written as JSON (like rawlog-edit --info).
#include <iostream>

#include "mbot/common/config.hpp"
#include "mbot/reports/dataset_summary.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

struct InspectOptions {
  std::string json_file = "inspect.json";
  bool print = true;
};

class InspectStage : public Stage {
 public:
  explicit InspectStage(InspectOptions o) : options_(std::move(o)) {}

  void OnEvent(const msgs::Event& ev) override { summary_.Add(ev); }

  void Finish(const RunContext& ctx, bool interrupted) override {
    std::string text;
    reports::Json json;
    summary_.Write(*ctx.source, ctx.source_path, interrupted, &text, &json);
    if (options_.print) std::cout << text << std::flush;
    if (!options_.json_file.empty()) reports::WriteJson(ctx.output_dir + "/" + options_.json_file, json);
  }

 private:
  InspectOptions options_;
  reports::DatasetSummary summary_;
};

}  // namespace

static StageType InspectStageType() {
  return {"inspect", "summary of a dataset: channels, generations, counts, rates, time span, beams, ground truth",
          [](config::Section& s) -> std::unique_ptr<Stage> {
            InspectOptions o;
            o.json_file = s.GetString("json_file", o.json_file, "summary file in output.dir ('' for none)");
            o.print = s.GetBool("print", o.print, "print the summary on stdout");
            return std::make_unique<InspectStage>(o);
          }};
}

const RegisterStage kInspectRegistered{InspectStageType()};

}  // namespace mbot::app
