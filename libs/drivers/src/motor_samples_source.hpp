// A motor calibration's samples as a source: the BeagleBone calibration CSV, one steady-state
// sample per line, `channel,duty,speed` (motor channel number, duty in [-1, 1] as sent, wheel speed
// in rad/s as the encoder measured it, raw signs). A header line `channel,duty,speed` and `#`
// comments are allowed. Each row becomes a kMotorSample event (t = row number in ms).
#pragma once

#include <string>
#include <vector>

#include "mbot/msgs/source.hpp"

namespace mbot::drivers {

using namespace msgs;  // the event vocabulary

// True when the file's first non-comment line is the header or three numbers.
bool IsMotorSamplesFile(const std::string& path);

class MotorSamplesSource : public Source {
 public:
  // Reads the whole file; throws std::runtime_error naming file and line on a malformed row.
  explicit MotorSamplesSource(const std::string& path);
  std::optional<Event> Next() override;
  double Progress() const override;
  std::string Format() const override { return "motor samples CSV"; }

 private:
  std::vector<Event> events_;
  size_t next_ = 0;
};

}  // namespace mbot::drivers
