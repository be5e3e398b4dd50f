// A summary of any dataset (inspect.json and the printed table): channels, message generation,
// counts, mean rates, time span, beams per scan, ranges, paths, maps, ground truth — like
// rawlog-edit --info.
#pragma once

#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "mbot/msgs/source.hpp"
#include "mbot/reports/json.hpp"

namespace mbot::reports {

struct ChannelStats {
  long long count = 0;
  int64_t first_us = 0;
  int64_t last_us = 0;
  long long backwards = 0;  // events whose time is earlier than the previous one on this channel
  msgs::EventKind kind = msgs::EventKind::kOther;
  // lidar
  size_t beams_min = SIZE_MAX, beams_max = 0;
  double beams_sum = 0;
  double range_min = INFINITY, range_max = 0;
  long long returns = 0, no_returns = 0;
  std::vector<double> spacing_deg;  // per-scan median beam spacing
  bool beam_times = false;
  // poses
  double path_m = 0;
  msgs::Pose2D first_pose, last_pose;
  // maps
  std::shared_ptr<const msgs::OccupancyGrid> map;
};

class DatasetSummary {
 public:
  void Add(const msgs::Event& ev);
  // The summary of what was added from `source` (its format, details, channels and diagnostics).
  // `text`: the printed form; `json`: inspect.json.
  void Write(const msgs::Source& source, const std::string& path, bool interrupted, std::string* text,
             Json* json) const;

 private:
  long long events_ = 0;
  long long backwards_ = 0;
  int64_t first_us_ = 0;
  int64_t last_us_ = INT64_MIN;
  std::map<std::string, ChannelStats> stats_;
};

}  // namespace mbot::reports
