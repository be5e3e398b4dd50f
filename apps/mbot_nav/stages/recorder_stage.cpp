// `recorder`: writes the event stream it sees to an LCM log (lcm-logger's format, the current
// mbot_lcm_msgs types), so a simulated run replays through the replay pipeline like a real robot's
// log. Put it last in [pipeline] stages: it then records what the source gave and everything earlier
// stages emitted (SLAM_POSE, MBOT_VEL_CMD). `channels` limits what is recorded.
#include <set>

#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/drivers/lcm_recorder.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

struct RecorderOptions {
  std::string file = "recording.log";  // in the output folder
  std::set<std::string> channels;      // empty: every channel that has an LCM message
};

class RecorderStage : public Stage {
 public:
  explicit RecorderStage(RecorderOptions o) : o_(std::move(o)) {}

  void Start(const RunContext& ctx) override {
    path_ = ctx.output_dir + "/" + o_.file;
    recorder_ = std::make_unique<drivers::LcmRecorder>(path_);
  }

  void OnEvent(const drivers::Event& ev) override {
    if (!o_.channels.empty() && !o_.channels.count(ev.channel)) return;
    recorder_->Record(ev);
  }

  void Finish(const RunContext& /*ctx*/, bool interrupted) override {
    if (!recorder_) return;
    recorder_->Close();
    std::string skipped;
    for (const auto& [channel, n] : recorder_->skipped())
      skipped += (skipped.empty() ? "" : ", ") + channel + " " + std::to_string(n);
    mbot::log::Info("recorder: " + std::to_string(recorder_->recorded()) + " messages to " + path_ +
                    (interrupted ? " (interrupted: everything up to the stop)" : "") +
                    (skipped.empty() ? "" : "; not recordable as LCM messages: " + skipped));
  }

 private:
  RecorderOptions o_;
  std::string path_;
  std::unique_ptr<drivers::LcmRecorder> recorder_;
};

}  // namespace

StageType RecorderStageType() {
  return {"recorder",
          "records the event stream as an LCM log (lcm-logger format, current mbot_lcm_msgs types) that the replay "
          "pipeline reads like a robot's log; last in the pipeline it also records what earlier stages emitted",
          [](config::Section& s) -> std::unique_ptr<Stage> {
            RecorderOptions o;
            o.file = s.GetString("file", o.file, "the log file, in the output folder");
            for (const std::string& c :
                 s.GetList("channels", {}, "record only these channels (empty: every recordable one)")) {
              o.channels.insert(c);
            }
            return std::make_unique<RecorderStage>(o);
          }};
}

}  // namespace mbot::app
