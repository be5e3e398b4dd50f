// Reads CARMEN text logs (plain or gzip): old FLASER/RLASER/ODOM/TRUEPOS lines and the newer
// ROBOTLASER1/2 and RAWLASER1-4 lines, with the project's own parser (MRPT 2.5.8's carmen2rawlog
// scales timestamps wrongly and assumes 0.5° beams).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "mbot/msgs/source.hpp"
#include "mbot/drivers/source_options.hpp"

namespace mbot::drivers {

using namespace msgs;  // the event vocabulary

class CarmenSource : public Source {
 public:
  explicit CarmenSource(const SourceOptions& options);
  std::optional<Event> Next() override;
  double Progress() const override;
  std::string Format() const override { return "CARMEN log"; }
  std::vector<std::pair<std::string, std::string>> Details() const override;

  // Beam geometry CARMEN uses for old-style lines that give only the number of readings
  // (carmen_laser_guess_fov / _angle_increment): 181/361 beams span 180°, 180/360 beams are
  // 1°/0.5° apart starting half a step in.
  static void GuessBeamGeometry(int num_beams, double* start_angle, double* increment);

 private:
  void ParseLine(const std::string& line, int line_no);

  SourceOptions options_;
  CarmenOptions carmen_;
  std::vector<Event> events_;
  size_t next_ = 0;
  double max_range_m_;
  int64_t lines_ = 0;
  int64_t ignored_lines_ = 0;
  int64_t duplicate_stamps_ = 0;
  int64_t backward_stamps_ = 0;  // carmen_order = file: records stamped before the one above
};

}  // namespace mbot::drivers
