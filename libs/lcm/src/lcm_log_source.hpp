// Replays an LCM log (any botlab message generation) as an Event stream.
#pragma once

#include <climits>
#include <deque>
#include <map>
#include <optional>
#include <set>
#include <string>

#include "mbot/lcm/lcm_log.hpp"
#include "mbot/msgs/source.hpp"
#include "mbot/lcm/lcm_sources.hpp"

namespace mbot::lcmio {

using namespace msgs;  // the event vocabulary

class LcmLogSource : public Source {
 public:
  explicit LcmLogSource(const SourceOptions& options);
  // Events come out in event-time order: records written slightly out of order (seen up to 3 ms in
  // maebot_convex.log) are re-sorted within LcmLogOptions::reorder_window_us.
  std::optional<Event> Next() override;
  double Progress() const override;
  std::string Format() const override { return "LCM log"; }

 private:
  std::optional<Event> ReadOne();

  SourceOptions options_;
  LcmLogOptions log_;
  std::deque<Event> pending_;  // sorted by t_us
  bool eof_ = false;
  int64_t last_emitted_us_ = INT64_MIN;
  LcmLogReader reader_;
  std::map<std::string, msgs::Pose2D> rezero_origin_;  // first pose per re-zeroed channel
  std::set<std::string> warned_unknown_;
};

}  // namespace mbot::lcmio
