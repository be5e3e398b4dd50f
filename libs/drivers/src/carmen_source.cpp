#include "carmen_source.hpp"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <sstream>
#include <stdexcept>

#include "mbot/common/log.hpp"

namespace mbot::drivers {

using namespace msgs;  // the event vocabulary
namespace {

// Splits on whitespace.
std::vector<std::string> Tokens(const std::string& line) {
  std::vector<std::string> t;
  std::istringstream in(line);
  std::string s;
  while (in >> s) t.push_back(s);
  return t;
}

struct ParseError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Reads tokens left to right with bounds and number checks.
class Cursor {
 public:
  explicit Cursor(const std::vector<std::string>& t) : t_(t) {}
  double Num(const char* what) {
    if (i_ >= t_.size()) throw ParseError(std::string("line ends before ") + what);
    char* end = nullptr;
    const double v = std::strtod(t_[i_].c_str(), &end);
    if (*end != '\0') throw ParseError(std::string("bad number '") + t_[i_] + "' for " + what);
    if (!std::isfinite(v) || std::abs(v) > 1e12)
      throw ParseError(std::string("'") + t_[i_] + "' for " + what + " is not a finite number");
    ++i_;
    return v;
  }
  // A range or remission: a non-finite value is a beam without a return (0).
  double Range(const char* what) {
    if (i_ >= t_.size()) throw ParseError(std::string("line ends before ") + what);
    char* end = nullptr;
    const double v = std::strtod(t_[i_].c_str(), &end);
    if (*end != '\0') throw ParseError(std::string("bad number '") + t_[i_] + "' for " + what);
    ++i_;
    return std::isfinite(v) ? v : 0.0;
  }
  int Count(const char* what, int max) {
    const double v = Num(what);
    if (v < 0 || v > max || v != std::floor(v)) throw ParseError(std::string("bad count for ") + what);
    return static_cast<int>(v);
  }
  void Skip(size_t n = 1) { i_ += n; }
  // After the timestamp a record carries the host name and the logger's timestamp, nothing more: more
  // tokens mean the counts did not describe the line (a record glued to the next, or a wrong count).
  void End() {
    if (left() > 2) {
      throw ParseError(std::to_string(left() - 2) + " tokens more than the record holds (after ipc_hostname and " +
                       "logger_timestamp)");
    }
  }
  size_t left() const { return i_ < t_.size() ? t_.size() - i_ : 0; }

 private:
  const std::vector<std::string>& t_;
  size_t i_ = 1;  // token 0 is the message name
};

int64_t Micros(double seconds) {
  int64_t t_us = 0;
  if (!StampFromSeconds(seconds, &t_us)) {
    throw ParseError("timestamp " + std::to_string(seconds) + " s is beyond the year 2100 either way");
  }
  return t_us;
}

}  // namespace

void CarmenSource::GuessBeamGeometry(int n, double* start, double* inc) {
  double fov = M_PI;
  if (n == 181 || n == 361) {
    *inc = M_PI / (n - 1);
  } else if (n == 180 || n == 360) {
    *inc = M_PI / n;
    fov = *inc * (n - 1);
  } else if (n == 401) {
    fov = 100.0 * M_PI / 180.0;
    *inc = fov / (n - 1);
  } else if (n == 400) {
    *inc = 100.0 * M_PI / 180.0 / n;
    fov = *inc * (n - 1);
  } else {
    *inc = n > 1 ? M_PI / (n - 1) : 0.0;
  }
  *start = -fov / 2.0;
}

CarmenSource::CarmenSource(const SourceOptions& options)
    : options_(options), carmen_(ExtraOr<CarmenOptions>(options)), max_range_m_(carmen_.max_range_m) {
  gzFile f = gzopen(options.path.c_str(), "rb");
  if (!f) throw std::runtime_error(options.path + ": cannot open CARMEN log");
  std::string line;
  char buf[1 << 16];
  int line_no = 0;
  constexpr size_t kMaxLine = 64 << 20;  // no CARMEN record comes near; a file without line ends does
  while (gzgets(f, buf, sizeof buf)) {
    line += buf;
    if (!line.empty() && line.back() != '\n' && !gzeof(f)) {  // a line longer than buf
      if (line.size() <= kMaxLine || line.find('\r') != std::string::npos) continue;
      mbot::log::Warn(options.path + ": line " + std::to_string(line_no + 1) +
                      " runs past 64 MB without a line end; the rest of the file is not read");
      diagnostics_.truncated_tail = true;
      break;
    }
    // Records end with LF, CRLF or (old Mac files) CR alone: each CR-separated piece is a line.
    for (size_t b = 0; b < line.size();) {
      size_t e = line.find('\r', b);
      if (e == std::string::npos) e = line.size();
      const std::string piece = line.substr(b, e - b);
      if (b == 0 || !(piece.empty() || piece == "\n")) ParseLine(piece, ++line_no);
      b = e + 1;
    }
    line.clear();
  }
  int err = 0;
  const char* msg = gzerror(f, &err);
  if (err != Z_OK && err != Z_STREAM_END) {
    mbot::log::Warn(options.path + ": read error after line " + std::to_string(line_no) + " (" + msg +
                    "); keeping what was read");
    diagnostics_.truncated_tail = true;
  }
  gzclose(f);
  bool file_order = carmen_.order == CarmenOptions::Order::kFile;
  if (carmen_.order == CarmenOptions::Order::kAuto) {
    int64_t latest = INT64_MIN, most_backwards = 0;
    for (const Event& ev : events_) {
      if (ev.stamp_us < latest) most_backwards = std::max(most_backwards, latest - ev.stamp_us);
      latest = std::max(latest, ev.stamp_us);
    }
    file_order = most_backwards < static_cast<int64_t>(CarmenOptions::kAutoOrderJitterS * 1e6);
    if (most_backwards > 0) {
      mbot::log::Info(options.path + ": stamps run backwards by up to " + std::to_string(most_backwards * 1e-6) +
                      " s: read in " + (file_order ? "file order (arrival-time jitter)" : "stamp order") +
                      " (carmen_order = auto)");
    }
  }
  if (file_order) {
    // File order: a record's event time is its stamp, or just after the record before when the stamp
    // runs backwards; the records of one line share it.
    int64_t last = INT64_MIN;
    for (size_t i = 0; i < events_.size(); ++i) {
      Event& ev = events_[i];
      if (i > 0 && ev.stamp_us == events_[i - 1].stamp_us) {
        ev.t_us = last;
        continue;
      }
      if (ev.stamp_us < last) ++backward_stamps_;
      ev.t_us = i == 0 ? ev.stamp_us : std::max(ev.stamp_us, last + 1);
      last = ev.t_us;
    }
    if (backward_stamps_ > 0) {
      mbot::log::Info(options.path + ": " + std::to_string(backward_stamps_) +
                      " records stamped before the record above them; kept in file order");
    }
  } else {
    std::stable_sort(events_.begin(), events_.end(), [](const Event& a, const Event& b) { return a.t_us < b.t_us; });
  }
  std::map<std::string, int64_t> last_scan;
  for (const Event& ev : events_) {
    if (ev.kind != EventKind::kLidar) continue;
    auto [it, first] = last_scan.emplace(ev.channel, ev.t_us);
    if (!first && it->second == ev.t_us) ++duplicate_stamps_;
    it->second = ev.t_us;
  }
  if (duplicate_stamps_ > 0) {
    mbot::log::Warn(options.path + ": " + std::to_string(duplicate_stamps_) +
                    " scans share their timestamp with the scan before them (timestamps printed with too "
                    "few digits?); file order is kept");
  }
}

void CarmenSource::ParseLine(const std::string& line, int line_no) {
  ++lines_;
  const auto t = Tokens(line);
  if (t.empty() || t[0][0] == '#') return;
  const std::string& name = t[0];
  Cursor c(t);
  auto fail = [&](const std::string& why) {
    ++diagnostics_.rejected_messages;
    mbot::log::Warn(options_.path + ":" + std::to_string(line_no) + ": rejected " + name + " line: " + why);
  };
  auto channel = [&](const std::string& ch, const char* type, EventKind kind) {
    auto& info = channels_[ch];
    info.type = type;
    info.kind = kind;
  };
  try {
    if (name == "FLASER" || name == "RLASER") {
      const int n = c.Count("num_readings", 4096);
      LidarScan scan;
      scan.ranges_m.resize(n);
      scan.angles_rad.resize(n);
      double start, inc;
      GuessBeamGeometry(n, &start, &inc);
      for (int i = 0; i < n; ++i) {
        scan.ranges_m[i] = static_cast<float>(c.Range("range"));
        scan.angles_rad[i] = static_cast<float>(start + i * inc);
      }
      scan.max_range_m = static_cast<float>(max_range_m_);
      const msgs::Pose2D pose{c.Num("x"), c.Num("y"), c.Num("theta")};
      const msgs::Pose2D odom{c.Num("odom_x"), c.Num("odom_y"), c.Num("odom_theta")};
      const int64_t ts = Micros(c.Num("ipc_timestamp"));
      c.End();
      // The laser pose (corrected in these logs) and the odometry fields stay apart.
      events_.push_back(Event{ts, ts, name, EventKind::kLidar, std::move(scan)});
      events_.push_back(Event{ts, ts, name + ".pose", EventKind::kReferencePose, pose});
      events_.push_back(Event{ts, ts, name + ".odom", EventKind::kOdometry, odom});
      channel(name, name == "FLASER" ? "FLASER (front laser)" : "RLASER (rear laser)", EventKind::kLidar);
      channel(name + ".pose", "laser pose fields", EventKind::kReferencePose);
      channel(name + ".odom", "odometry fields", EventKind::kOdometry);
    } else if (name == "ODOM") {
      const msgs::Pose2D pose{c.Num("x"), c.Num("y"), c.Num("theta")};
      c.Skip(3);  // tv rv accel
      const int64_t ts = Micros(c.Num("ipc_timestamp"));
      c.End();
      events_.push_back(Event{ts, ts, name, EventKind::kOdometry, pose});
      channel(name, "ODOM", EventKind::kOdometry);
    } else if (name == "TRUEPOS") {
      const msgs::Pose2D truth{c.Num("true_x"), c.Num("true_y"), c.Num("true_theta")};
      c.Skip(3);
      const int64_t ts = Micros(c.Num("ipc_timestamp"));
      c.End();
      events_.push_back(Event{ts, ts, name, EventKind::kGroundTruth, truth});
      channel(name, "TRUEPOS", EventKind::kGroundTruth);
    } else if (name.rfind("ROBOTLASER", 0) == 0 || name.rfind("RAWLASER", 0) == 0) {
      const bool robot = name[1] == 'O';
      c.Skip();  // laser_type
      const double start = c.Num("start_angle");
      c.Num("field_of_view");
      const double inc = c.Num("angular_resolution");
      const double max_range = c.Num("maximum_range");
      c.Skip(2);  // accuracy, remission_mode
      const int n = c.Count("num_readings", 4096);
      LidarScan scan;
      scan.ranges_m.resize(n);
      scan.angles_rad.resize(n);
      for (int i = 0; i < n; ++i) {
        scan.ranges_m[i] = static_cast<float>(c.Range("range"));
        scan.angles_rad[i] = static_cast<float>(start + i * inc);
      }
      const int nr = c.Count("num_remissions", 4096);
      scan.intensities.resize(nr);
      for (int i = 0; i < nr; ++i) scan.intensities[i] = static_cast<float>(c.Range("remission"));
      scan.max_range_m = static_cast<float>(max_range);
      int64_t ts;
      if (robot) {
        const msgs::Pose2D laser{c.Num("laser_x"), c.Num("laser_y"), c.Num("laser_theta")};
        const msgs::Pose2D robot_pose{c.Num("robot_x"), c.Num("robot_y"), c.Num("robot_theta")};
        c.Skip(5);  // tv rv forward_safety side_safety turn_axis
        ts = Micros(c.Num("timestamp"));
        c.End();
        // Sensor offset on the robot, from the two poses the line gives. In a raw log (the Freiburg
        // hospital's, with no ODOM lines) the robot pose is the odometry at the scan.
        scan.sensor_pose = robot_pose.Inverse().Compose(laser);
        events_.push_back(Event{ts, ts, name + ".odom", EventKind::kOdometry, robot_pose});
        channel(name + ".odom", "robot pose fields (odometry)", EventKind::kOdometry);
      } else {
        ts = Micros(c.Num("timestamp"));
        c.End();
      }
      events_.push_back(Event{ts, ts, name, EventKind::kLidar, std::move(scan)});
      channel(name, robot ? "ROBOTLASER" : "RAWLASER", EventKind::kLidar);
    } else if (name == "PARAM") {
      if (t.size() >= 3 && t[1] == "robot_front_laser_max") {
        max_range_m_ = std::strtod(t[2].c_str(), nullptr);
        if (!(max_range_m_ > 0 && max_range_m_ <= 1e4)) max_range_m_ = carmen_.max_range_m;
      }
      ++ignored_lines_;
    } else {
      ++ignored_lines_;  // NEFF, SYNC, PARAM and other messages the pipeline does not use
      auto& info = channels_[name];
      info.type = name + " (not used)";
      info.kind = EventKind::kOther;
    }
  } catch (const ParseError& e) {
    fail(e.what());
  }
}

std::optional<Event> CarmenSource::Next() {
  if (next_ >= events_.size()) return std::nullopt;
  return std::move(events_[next_++]);
}

double CarmenSource::Progress() const { return events_.empty() ? 1.0 : double(next_) / double(events_.size()); }

std::vector<std::pair<std::string, std::string>> CarmenSource::Details() const {
  return {{"lines", std::to_string(lines_)},
          {"lines not used (PARAM, NEFF, …)", std::to_string(ignored_lines_)},
          {"scans sharing a timestamp", std::to_string(duplicate_stamps_)}};
}

}  // namespace mbot::drivers
