// Replays an MRPT rawlog, in either format: Actions/SensoryFrame pairs or observations only.
#pragma once

#include <deque>
#include <optional>
#include <string>

#include "mbot/msgs/source.hpp"
#include "mbot/drivers/source_options.hpp"

namespace mbot::drivers {

using namespace msgs;  // the event vocabulary

class RawlogSource : public Source {
 public:
  explicit RawlogSource(const SourceOptions& options);
  std::optional<Event> Next() override;
  double Progress() const override;
  std::string Format() const override;
  std::vector<std::pair<std::string, std::string>> Details() const override;

 private:
  std::vector<Event> events_;  // whole file, stably sorted by time
  size_t next_ = 0;
  size_t actions_ = 0;
  size_t sensory_frames_ = 0;
  size_t observations_ = 0;  // stand-alone observations (observations-only format)
  size_t invalid_stamps_ = 0;
};

}  // namespace mbot::drivers
