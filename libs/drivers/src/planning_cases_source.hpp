// Planner benchmark files as a source: botlab A* cases (`<name>_poses.txt` beside `<name>.map`, or
// a folder of them) and Moving AI scenario files (`.map.scen`). Each map is emitted as a kMap event
// on a channel named after it, followed by its cases as kPlanRequest events on the same channel.
#pragma once

#include <string>
#include <vector>

#include "mbot/msgs/source.hpp"

namespace mbot::drivers {

using namespace msgs;  // the event vocabulary

// True for a botlab poses file, a folder holding some, or a Moving AI scenario file.
bool IsPlanningCasesPath(const std::string& path, std::string* format = nullptr);

class PlanningCasesSource : public Source {
 public:
  // `format`: "astar_cases" or "movingai". Reads every file up front and throws
  // std::runtime_error naming file and line on malformed content.
  PlanningCasesSource(const std::string& path, const std::string& format);
  std::optional<Event> Next() override;
  double Progress() const override;
  std::string Format() const override { return format_; }

 private:
  std::string format_;
  std::vector<Event> events_;
  size_t next_ = 0;
};

}  // namespace mbot::drivers
