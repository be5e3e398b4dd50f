#include "mbot/lcm/lcm_sources.hpp"

#include <fstream>
#include <map>

#include "lcm_live_source.hpp"
#include "lcm_log_source.hpp"
#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/lcm/lcm_live.hpp"
#include "mbot/lcm/lcm_log.hpp"
#include "mbot/lcm/lcm_recorder.hpp"
#include "mbot/msgs/stage.hpp"

namespace mbot::lcmio {

using namespace msgs;  // the event vocabulary

// lcm_relay.cpp, lcm_bridge_stage.cpp
std::unique_ptr<Source> OpenLcmRelay(const SourceOptions& options);
StageType LcmBridgeStageType();

namespace {

bool IsLcmLog(const std::string& path) {
  unsigned char head[4] = {0, 0, 0, 0};
  std::ifstream in(path, std::ios::binary);
  in.read(reinterpret_cast<char*>(head), 4);
  const uint32_t word = (uint32_t(head[0]) << 24) | (uint32_t(head[1]) << 16) | (uint32_t(head[2]) << 8) | head[3];
  return in.gcount() == 4 && word == LcmLogReader::kSyncWord;
}

void ParseLcmLogOptions(config::Section& s, SourceOptions* o) {
  ParseChannelRoles(s, &o->roles);
  LcmLogOptions l;
  l.reorder_window_us = static_cast<int64_t>(
      1e6 * s.GetDouble("reorder_window_s", l.reorder_window_us * 1e-6,
                        "lcm_log: records are re-sorted by event time within this window [s]", 0.0, 10.0));
  o->extra = l;
}

// output lcm: the run's events on the LCM bus, as the botlab's messages, on their channels (renamed
// by `rename`). Kinds with no LCM message are counted, not sent.
class LcmPublishOutput : public Output {
 public:
  LcmPublishOutput(std::string url, TopicTable names) : url_(std::move(url)), names_(std::move(names)) {}
  void Open(const RunContext& /*ctx*/) override {
    node_ = std::make_unique<LcmNode>(url_, std::vector<std::string>{}, ChannelRoles{});
    mbot::log::Info("output lcm: publishing on " + url_);
  }
  void Send(const Event& event) override {
    Event e = event;
    e.channel = names_.Wire(event.channel);
    if (!node_->Publish(e)) ++unsent_[ToString(event.kind)];
  }
  void Close(bool /*interrupted*/) override {
    std::string skipped;
    for (const auto& [kind, n] : unsent_) skipped += (skipped.empty() ? "" : ", ") + kind + " " + std::to_string(n);
    if (!skipped.empty()) mbot::log::Info("output lcm: no LCM message for " + skipped);
  }

 private:
  std::string url_;
  TopicTable names_;
  std::unique_ptr<LcmNode> node_;
  std::map<std::string, long long> unsent_;
};

// output lcm_log: the run's events as an LCM log (lcm-logger's format, the current mbot_lcm_msgs
// types) that the replay pipeline reads like a robot's log: what the source gave and everything the
// stages emitted (SLAM_POSE, MBOT_VEL_CMD). Written to a temporary file and renamed at the end.
class LcmLogOutput : public Output {
 public:
  LcmLogOutput(std::string file, TopicTable names) : file_(std::move(file)), names_(std::move(names)) {}
  void Open(const RunContext& ctx) override {
    path_ = ctx.output_dir + "/" + file_;
    recorder_ = std::make_unique<LcmRecorder>(path_);
  }
  void Send(const Event& event) override {
    Event e = event;
    e.channel = names_.Wire(event.channel);
    recorder_->Record(e);
  }
  void Close(bool interrupted) override {
    if (!recorder_) return;
    recorder_->Close();
    std::string skipped;
    for (const auto& [channel, n] : recorder_->skipped())
      skipped += (skipped.empty() ? "" : ", ") + channel + " " + std::to_string(n);
    mbot::log::Info("output lcm_log: " + std::to_string(recorder_->recorded()) + " messages to " + path_ +
                    (interrupted ? " (interrupted: everything up to the stop)" : "") +
                    (skipped.empty() ? "" : "; not recordable as LCM messages: " + skipped));
  }

 private:
  std::string file_, path_;
  TopicTable names_;
  std::unique_ptr<LcmRecorder> recorder_;
};

}  // namespace

void RegisterLcmTransport() {
  if (FindSourceType("lcm_log")) return;
  RegisterSourceType({"lcm_log", "an LCM log (lcm-logger), every botlab message generation", IsLcmLog, 10,
                      ParseLcmLogOptions, [](const SourceOptions& o) { return std::make_unique<LcmLogSource>(o); }});
  SourceType live{"lcm_live",
                  "a robot (or the simulated one) on the LCM bus, in wall-clock time; url is the LCM url",
                  nullptr,
                  0,
                  [](config::Section& s, SourceOptions* o) {
                    ParseChannelRoles(s, &o->roles);
                    o->extra = ParseLiveSourceOptions(s, "lcm_live");
                  },
                  OpenLcmLive};
  live.default_url = kDefaultLcmUrl;
  RegisterSourceType(std::move(live));
  SourceType relay{"lcm_relay",
                   "a fault-injecting relay between the robot's LCM group (url) and the autonomy's (relay_url): "
                   "drops, delay, jitter, duplicates, reordering, corruption, silences",
                   nullptr,
                   0,
                   ParseRelayOptions,
                   OpenLcmRelay};
  relay.default_url = kDefaultLcmUrl;
  RegisterSourceType(std::move(relay));

  RegisterOutputType({"lcm", "publishes the run's events on the LCM bus as the botlab's messages (lcm-spy, a viewer)",
                      [](config::Section& s) -> std::unique_ptr<Output> {
                        const std::string url =
                            s.GetString("url", kDefaultLcmUrl, "the LCM URL (ttl=0 keeps the traffic on this machine)");
                        TopicTable names;
                        names.Parse(s, "rename");
                        return std::make_unique<LcmPublishOutput>(url, std::move(names));
                      },
                      false, ""});
  RegisterOutputType({"lcm_log",
                      "records the run's events as an LCM log (lcm-logger format, current mbot_lcm_msgs types) that "
                      "the replay pipeline reads like a robot's log",
                      [](config::Section& s) -> std::unique_ptr<Output> {
                        const std::string file =
                            s.GetString("file", "recording.log", "the log file, in the output folder");
                        TopicTable names;
                        names.Parse(s, "rename");
                        return std::make_unique<LcmLogOutput>(file, std::move(names));
                      },
                      true, ""});
  RegisterStageType(LcmBridgeStageType());
}

}  // namespace mbot::lcmio
