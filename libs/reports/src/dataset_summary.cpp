#include "mbot/reports/dataset_summary.hpp"

#include <algorithm>
#include <iomanip>
#include <sstream>

#include "mbot/common/strings.hpp"

namespace mbot::reports {
namespace {

using msgs::EventKind;

}  // namespace

void DatasetSummary::Add(const msgs::Event& ev) {
  if (events_ == 0) first_us_ = ev.t_us;
  if (events_ > 0 && ev.t_us < last_us_) ++backwards_;
  last_us_ = std::max(last_us_, ev.t_us);
  ++events_;
  ChannelStats& c = stats_[ev.channel];
  if (c.count > 0 && ev.t_us < c.last_us) ++c.backwards;
  if (c.count == 0) c.first_us = ev.t_us;
  c.last_us = std::max(c.last_us, ev.t_us);
  ++c.count;
  c.kind = ev.kind;
  if (const auto* scan = std::get_if<msgs::LidarScan>(&ev.payload)) {
    const size_t n = scan->ranges_m.size();
    c.beams_min = std::min(c.beams_min, n);
    c.beams_max = std::max(c.beams_max, n);
    c.beams_sum += n;
    c.beam_times |= !scan->beam_times_us.empty();
    for (float r : scan->ranges_m) {
      const bool no_return = !std::isfinite(r) || r <= 0.0f || (scan->max_range_m > 0 && r >= scan->max_range_m);
      if (no_return) {
        ++c.no_returns;
        continue;
      }
      ++c.returns;
      c.range_min = std::min<double>(c.range_min, r);
      c.range_max = std::max<double>(c.range_max, r);
    }
    std::vector<double> d;
    for (size_t i = 1; i < scan->angles_rad.size(); ++i) {
      d.push_back(std::abs(msgs::WrapAngle(scan->angles_rad[i] - scan->angles_rad[i - 1])) * 180.0 / M_PI);
    }
    if (!d.empty()) c.spacing_deg.push_back(Median(d));
  } else if (const auto* pose = std::get_if<msgs::Pose2D>(&ev.payload)) {
    if (c.count == 1)
      c.first_pose = *pose;
    else
      c.path_m += std::hypot(pose->x - c.last_pose.x, pose->y - c.last_pose.y);
    c.last_pose = *pose;
  } else if (const auto* map = std::get_if<std::shared_ptr<const msgs::OccupancyGrid>>(&ev.payload)) {
    c.map = *map;
  }
}

void DatasetSummary::Write(const msgs::Source& source, const std::string& path, bool interrupted, std::string* out_text,
                           Json* out_json) const {
  const msgs::Source& src = source;
  bool ground_truth = false;
  for (const auto& [name, c] : stats_) ground_truth |= c.kind == EventKind::kGroundTruth;
  std::ostringstream text;
  Json& json = *out_json;
  json = Json();
  const double span = (last_us_ - first_us_) * 1e-6;
  text << "dataset:      " << path << "\n"
       << "format:       " << src.Format() << "\n";
  for (const auto& [k, v] : src.Details()) text << "  " << k << ": " << v << "\n";
  text << "events:       " << events_ << (interrupted ? " (interrupted)" : "") << "\n"
       << "time span:    " << std::fixed << std::setprecision(3) << span << " s\n"
       << "event time:   " << (backwards_ == 0 ? "monotonic" : std::to_string(backwards_) + " steps backwards") << "\n"
       << "ground truth: " << (ground_truth ? "yes" : "no") << "\n";
  const auto& d = src.diagnostics();
  text << "problems:     " << d.rejected_messages << " rejected, " << d.unknown_messages << " of unknown type, "
       << d.resyncs << " resyncs (" << d.skipped_bytes << " bytes skipped)"
       << (d.truncated_tail ? ", truncated tail" : "") << "\n\n";
  text << std::left << std::setw(24) << "channel" << std::setw(34) << "type" << std::setw(30) << "generation"
       << std::setw(15) << "role" << std::right << std::setw(8) << "count" << std::setw(10) << "rate Hz"
       << "\n";
  json["dataset"] = path;
  json["format"] = src.Format();
  json["events"] = events_;
  json["interrupted"] = interrupted;
  json["time_span_s"] = Number(span, 9);
  json["event_time_backwards_steps"] = backwards_;
  json["ground_truth"] = ground_truth;
  json["rejected_messages"] = d.rejected_messages;
  json["unknown_messages"] = d.unknown_messages;
  json["resyncs"] = d.resyncs;
  json["truncated_tail"] = d.truncated_tail;
  json["details"] = Json::object();
  for (const auto& [k, v] : src.Details()) json["details"][k] = v;
  json["channels"] = Json::object();
  std::ostringstream extra;
  for (const auto& [name, info] : src.channels()) {
    auto it = stats_.find(name);
    const ChannelStats empty;
    const ChannelStats& c = it == stats_.end() ? empty : it->second;
    const double cspan = (c.last_us - c.first_us) * 1e-6;
    const double rate = c.count > 1 && cspan > 0 ? (c.count - 1) / cspan : NAN;
    text << std::left << std::setw(24) << name << std::setw(34) << info.type.substr(0, 33) << std::setw(30)
         << (info.generation.empty() ? "-" : info.generation.substr(0, 29)) << std::setw(15)
         << (info.decoded ? msgs::ToString(info.kind) : "skipped") << std::right << std::setw(8) << c.count
         << std::setw(10) << (std::isfinite(rate) ? Num(rate, 4) : "-") << "\n";
    Json& cj = json["channels"][name];
    cj = {{"type", info.type},
          {"generation", info.generation},
          {"role", info.decoded ? msgs::ToString(info.kind) : "skipped"},
          {"count", c.count},
          {"rate_hz", Number(rate)},
          {"first_s", Number(c.first_us * 1e-6, 16)},
          {"last_s", Number(c.last_us * 1e-6, 16)},
          {"backwards_steps", c.backwards}};
    if (c.beams_max > 0) {
      const double spacing = Median(c.spacing_deg);
      extra << "  " << name << ": " << c.beams_min << "-" << c.beams_max << " beams per scan (mean "
            << Num(c.beams_sum / c.count, 5) << "), beam spacing " << Num(spacing, 4) << " deg, ranges "
            << Num(c.range_min, 4) << "-" << Num(c.range_max, 4) << " m, " << c.no_returns << " no-returns"
            << (c.beam_times ? ", per-beam times" : "") << "\n";
      cj["beams_min"] = c.beams_min;
      cj["beams_max"] = c.beams_max;
      cj["beams_mean"] = Number(c.beams_sum / c.count);
      cj["beam_spacing_deg"] = Number(spacing);
      cj["range_min_m"] = Number(c.range_min);
      cj["range_max_m"] = Number(c.range_max);
      cj["returns"] = c.returns;
      cj["no_returns"] = c.no_returns;
      cj["beam_times"] = c.beam_times;
    }
    if (c.kind == EventKind::kOdometry || c.kind == EventKind::kGroundTruth || c.kind == EventKind::kReferencePose) {
      extra << "  " << name << ": path " << Num(c.path_m, 4) << " m, from (" << Num(c.first_pose.x, 4) << ", "
            << Num(c.first_pose.y, 4) << ", " << Num(c.first_pose.theta, 4) << ") to (" << Num(c.last_pose.x, 4) << ", "
            << Num(c.last_pose.y, 4) << ", " << Num(c.last_pose.theta, 4) << ")\n";
      cj["path_m"] = Number(c.path_m);
    }
    if (c.map) {
      const auto cells = c.map->CountCells();
      extra << "  " << name << ": " << c.map->width() << "x" << c.map->height() << " cells of "
            << Num(c.map->resolution()) << " m, origin (" << Num(c.map->origin_x()) << ", " << Num(c.map->origin_y())
            << "), " << cells.occupied << " occupied, " << cells.free << " free, " << cells.unknown << " unknown\n";
      cj["map"] = {{"width", c.map->width()},
                   {"height", c.map->height()},
                   {"resolution_m", Number(c.map->resolution())},
                   {"origin_x_m", Number(c.map->origin_x())},
                   {"origin_y_m", Number(c.map->origin_y())},
                   {"occupied", cells.occupied},
                   {"free", cells.free},
                   {"unknown", cells.unknown}};
    }
  }
  if (!extra.str().empty()) text << "\n" << extra.str();
  *out_text = text.str();
}

}  // namespace mbot::reports
