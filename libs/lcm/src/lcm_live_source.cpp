#include "lcm_live_source.hpp"

#include "mbot/common/log.hpp"
#include "mbot/lcm/lcm_live.hpp"

namespace mbot::lcmio {

using namespace msgs;  // the event vocabulary
namespace {

class LcmLink : public LiveLink {
 public:
  LcmLink(const std::string& url, const std::vector<std::string>& channels, const ChannelRoles& roles)
      : node_(url, channels, roles) {}
  void Poll(int timeout_ms, std::vector<Event>* out) override { node_.Poll(timeout_ms, out); }
  bool Publish(const Event& event) override { return node_.Publish(event); }
  long long rejected_total() const override { return node_.rejected_total(); }
  std::string name() const override { return "lcm"; }
  std::string where() const override { return node_.url(); }
  ChannelInfo Describe(const std::string& /*channel*/) const override {
    return ChannelInfo{"mbot_lcm_msgs", "2023+", EventKind::kOther, true};
  }
  std::vector<std::pair<std::string, std::string>> Details() const override {
    std::vector<std::pair<std::string, std::string>> d;
    for (const auto& [channel, s] : node_.stats()) {
      if (s.rejected + s.unknown > 0)
        d.push_back({"rejected on " + channel, std::to_string(s.rejected + s.unknown) + " (" + s.last_error + ")"});
      if (s.own_echoes > 0) d.push_back({"own messages looped back on " + channel, std::to_string(s.own_echoes)});
    }
    return d;
  }

 private:
  LcmNode node_;
};

}  // namespace

std::unique_ptr<Source> OpenLcmLive(const SourceOptions& options) {
  const LiveSourceOptions o = ExtraOr<LiveSourceOptions>(options);
  return std::make_unique<LiveSource>(std::make_unique<LcmLink>(options.path, o.channels, options.roles), o,
                                      "live LCM");
}

}  // namespace mbot::lcmio
