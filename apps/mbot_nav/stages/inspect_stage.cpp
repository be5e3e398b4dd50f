// `inspect`: a summary of any dataset — channels, message generation, counts, mean rates, time
// span, beams per scan, ranges, ground truth — printed and written as JSON (like rawlog-edit --info).
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/config.hpp"
#include "report.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

using drivers::Event;
using drivers::EventKind;

struct ChannelStats {
  long long count = 0;
  int64_t first_us = 0;
  int64_t last_us = 0;
  long long backwards = 0;  // events whose time is earlier than the previous one on this channel
  EventKind kind = EventKind::kOther;
  // lidar
  size_t beams_min = SIZE_MAX, beams_max = 0;
  double beams_sum = 0;
  double range_min = INFINITY, range_max = 0;
  long long returns = 0, no_returns = 0;
  std::vector<double> spacing_deg;  // per-scan median beam spacing
  bool beam_times = false;
  // poses
  double path_m = 0;
  motion::Pose2D first_pose, last_pose;
  // maps
  std::shared_ptr<const mapping::OccupancyGrid> map;
};

struct InspectOptions {
  std::string json_file = "inspect.json";
  bool print = true;
};

class InspectStage : public Stage {
 public:
  explicit InspectStage(InspectOptions o) : options_(std::move(o)) {}

  void OnEvent(const Event& ev) override {
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
    if (const auto* scan = std::get_if<drivers::LidarScan>(&ev.payload)) {
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
        d.push_back(std::abs(motion::WrapAngle(scan->angles_rad[i] - scan->angles_rad[i - 1])) * 180.0 / M_PI);
      }
      if (!d.empty()) c.spacing_deg.push_back(Median(d));
    } else if (const auto* pose = std::get_if<motion::Pose2D>(&ev.payload)) {
      if (c.count == 1)
        c.first_pose = *pose;
      else
        c.path_m += std::hypot(pose->x - c.last_pose.x, pose->y - c.last_pose.y);
      c.last_pose = *pose;
    } else if (const auto* map = std::get_if<std::shared_ptr<const mapping::OccupancyGrid>>(&ev.payload)) {
      c.map = *map;
    }
  }

  void Finish(const RunContext& ctx, bool interrupted) override {
    const drivers::Source& src = *ctx.source;
    bool ground_truth = false;
    for (const auto& [name, c] : stats_) ground_truth |= c.kind == EventKind::kGroundTruth;
    std::ostringstream text, json;
    const double span = (last_us_ - first_us_) * 1e-6;
    text << "dataset:      " << ctx.source_path << "\n"
         << "format:       " << src.Format() << "\n";
    for (const auto& [k, v] : src.Details()) text << "  " << k << ": " << v << "\n";
    text << "events:       " << events_ << (interrupted ? " (interrupted)" : "") << "\n"
         << "time span:    " << std::fixed << std::setprecision(3) << span << " s\n"
         << "event time:   " << (backwards_ == 0 ? "monotonic" : std::to_string(backwards_) + " steps backwards")
         << "\n"
         << "ground truth: " << (ground_truth ? "yes" : "no") << "\n";
    const auto& d = src.diagnostics();
    text << "problems:     " << d.rejected_messages << " rejected, " << d.unknown_messages << " of unknown type, "
         << d.resyncs << " resyncs (" << d.skipped_bytes << " bytes skipped)"
         << (d.truncated_tail ? ", truncated tail" : "") << "\n\n";
    text << std::left << std::setw(24) << "channel" << std::setw(34) << "type" << std::setw(30) << "generation"
         << std::setw(15) << "role" << std::right << std::setw(8) << "count" << std::setw(10) << "rate Hz"
         << "\n";
    json << "{\n  \"dataset\": " << JsonString(ctx.source_path) << ",\n  \"format\": " << JsonString(src.Format())
         << ",\n  \"events\": " << events_ << ",\n  \"interrupted\": " << (interrupted ? "true" : "false")
         << ",\n  \"time_span_s\": " << Num(span, 9) << ",\n  \"event_time_backwards_steps\": " << backwards_
         << ",\n  \"ground_truth\": " << (ground_truth ? "true" : "false")
         << ",\n  \"rejected_messages\": " << d.rejected_messages << ",\n  \"unknown_messages\": " << d.unknown_messages
         << ",\n  \"resyncs\": " << d.resyncs << ",\n  \"truncated_tail\": " << (d.truncated_tail ? "true" : "false")
         << ",\n  \"details\": {";
    bool first = true;
    for (const auto& [k, v] : src.Details()) {
      json << (first ? "" : ", ") << JsonString(k) << ": " << JsonString(v);
      first = false;
    }
    json << "},\n  \"channels\": {";
    std::ostringstream extra;
    first = true;
    for (const auto& [name, info] : src.channels()) {
      auto it = stats_.find(name);
      const ChannelStats empty;
      const ChannelStats& c = it == stats_.end() ? empty : it->second;
      const double cspan = (c.last_us - c.first_us) * 1e-6;
      const double rate = c.count > 1 && cspan > 0 ? (c.count - 1) / cspan : NAN;
      text << std::left << std::setw(24) << name << std::setw(34) << info.type.substr(0, 33) << std::setw(30)
           << (info.generation.empty() ? "-" : info.generation.substr(0, 29)) << std::setw(15)
           << (info.decoded ? drivers::ToString(info.kind) : "skipped") << std::right << std::setw(8) << c.count
           << std::setw(10) << (std::isfinite(rate) ? Num(rate, 4) : "-") << "\n";
      json << (first ? "" : ",") << "\n    " << JsonString(name) << ": {\"type\": " << JsonString(info.type)
           << ", \"generation\": " << JsonString(info.generation)
           << ", \"role\": " << JsonString(info.decoded ? drivers::ToString(info.kind) : "skipped")
           << ", \"count\": " << c.count << ", \"rate_hz\": " << Num(rate)
           << ", \"first_s\": " << Num(c.first_us * 1e-6, 16) << ", \"last_s\": " << Num(c.last_us * 1e-6, 16)
           << ", \"backwards_steps\": " << c.backwards;
      first = false;
      if (c.beams_max > 0) {
        const double spacing = Median(c.spacing_deg);
        extra << "  " << name << ": " << c.beams_min << "-" << c.beams_max << " beams per scan (mean "
              << Num(c.beams_sum / c.count, 5) << "), beam spacing " << Num(spacing, 4) << " deg, ranges "
              << Num(c.range_min, 4) << "-" << Num(c.range_max, 4) << " m, " << c.no_returns << " no-returns"
              << (c.beam_times ? ", per-beam times" : "") << "\n";
        json << ", \"beams_min\": " << c.beams_min << ", \"beams_max\": " << c.beams_max
             << ", \"beams_mean\": " << Num(c.beams_sum / c.count) << ", \"beam_spacing_deg\": " << Num(spacing)
             << ", \"range_min_m\": " << Num(c.range_min) << ", \"range_max_m\": " << Num(c.range_max)
             << ", \"returns\": " << c.returns << ", \"no_returns\": " << c.no_returns
             << ", \"beam_times\": " << (c.beam_times ? "true" : "false");
      }
      if (c.kind == EventKind::kOdometry || c.kind == EventKind::kGroundTruth || c.kind == EventKind::kReferencePose) {
        extra << "  " << name << ": path " << Num(c.path_m, 4) << " m, from (" << Num(c.first_pose.x, 4) << ", "
              << Num(c.first_pose.y, 4) << ", " << Num(c.first_pose.theta, 4) << ") to (" << Num(c.last_pose.x, 4)
              << ", " << Num(c.last_pose.y, 4) << ", " << Num(c.last_pose.theta, 4) << ")\n";
        json << ", \"path_m\": " << Num(c.path_m);
      }
      if (c.map) {
        const auto cells = c.map->CountCells();
        extra << "  " << name << ": " << c.map->width() << "x" << c.map->height() << " cells of "
              << Num(c.map->resolution()) << " m, origin (" << Num(c.map->origin_x()) << ", " << Num(c.map->origin_y())
              << "), " << cells.occupied << " occupied, " << cells.free << " free, " << cells.unknown << " unknown\n";
        json << ", \"map\": {\"width\": " << c.map->width() << ", \"height\": " << c.map->height()
             << ", \"resolution_m\": " << Num(c.map->resolution()) << ", \"origin_x_m\": " << Num(c.map->origin_x())
             << ", \"origin_y_m\": " << Num(c.map->origin_y()) << ", \"occupied\": " << cells.occupied
             << ", \"free\": " << cells.free << ", \"unknown\": " << cells.unknown << "}";
      }
      json << "}";
    }
    json << "\n  }\n}\n";
    if (!extra.str().empty()) text << "\n" << extra.str();
    if (options_.print) std::cout << text.str() << std::flush;
    if (!options_.json_file.empty()) {
      const std::string out = ctx.output_dir + "/" + options_.json_file;
      WriteFileAtomically(out, [&](std::ostream& o) { o << json.str(); });
    }
  }

 private:
  InspectOptions options_;
  long long events_ = 0;
  long long backwards_ = 0;
  int64_t first_us_ = 0;
  int64_t last_us_ = INT64_MIN;
  std::map<std::string, ChannelStats> stats_;
};

}  // namespace

StageType InspectStageType() {
  return {"inspect", "summary of a dataset: channels, generations, counts, rates, time span, beams, ground truth",
          [](config::Section& s) -> std::unique_ptr<Stage> {
            InspectOptions o;
            o.json_file = s.GetString("json_file", o.json_file, "summary file in output.dir ('' for none)");
            o.print = s.GetBool("print", o.print, "print the summary on stdout");
            return std::make_unique<InspectStage>(o);
          }};
}

}  // namespace mbot::app
