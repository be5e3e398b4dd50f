#include "mbot/drivers/source_options.hpp"

#include "mbot/common/files.hpp"

#include <zlib.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <algorithm>
#include <deque>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "camera_source.hpp"
#include "carmen_source.hpp"
#include "mbot/common/config.hpp"
#include "mbot/common/strings.hpp"
#include "mbot/drivers/map_io.hpp"
#include "motor_samples_source.hpp"
#include "planning_cases_source.hpp"
#include "rawlog_source.hpp"

namespace mbot::drivers {

using namespace msgs;  // the event vocabulary
namespace {

// A map file as a source: one kMap event at t = 0.
class MapSource : public Source {
 public:
  explicit MapSource(const std::string& path) {
    grid_ = std::make_shared<OccupancyGrid>(ReadAnyMap(path, &format_));
    channels_["map"] = ChannelInfo{format_, "", EventKind::kMap, true};
  }
  std::optional<Event> Next() override {
    if (done_) return std::nullopt;
    done_ = true;
    return Event{0, 0, "map", EventKind::kMap, std::shared_ptr<const OccupancyGrid>(grid_)};
  }
  double Progress() const override { return done_ ? 1.0 : 0.0; }
  std::string Format() const override { return format_; }

 private:
  std::shared_ptr<OccupancyGrid> grid_;
  std::string format_;
  bool done_ = false;
};

void ParseCameraSourceOptions(config::Section& s, SourceOptions* out) {
  CameraSourceOptions o;
  auto doc = [](const char* text) { return std::string("type = camera: ") + text; };
  o.fps =
      s.GetDouble("camera_fps", o.fps, doc("replay: frames 1/fps apart; a device is asked for this rate"), 0.1, 1000.0);
  o.width =
      static_cast<int>(s.GetInt("camera_width", o.width, doc("a device is asked for this width [px]"), 16, 10000));
  o.height =
      static_cast<int>(s.GetInt("camera_height", o.height, doc("a device is asked for this height [px]"), 16, 10000));
  o.timeout_s = s.GetDouble("camera_timeout_s", o.timeout_s,
                            doc("a live camera silent this long ends the stream, reported [s]"), 0.01, 3600.0);
  o.channel = s.GetString("camera_channel", o.channel, doc("the channel the frames are emitted on"));
  o.color = s.GetBool("camera_color", o.color,
                      doc("colour frames (BGR) as the images are, instead of grey (calibration and detection "
                          "pictures are drawn on them)"));
  out->extra = o;
}

void ParseCarmenOptions(config::Section& s, SourceOptions* out) {
  CarmenOptions o;
  o.max_range_m = s.GetDouble("carmen_max_range_m", o.max_range_m,
                              "CARMEN FLASER range limit when the log's PARAM lines do not give one [m]", 0.1, 1000.0);
  o.order = s.GetEnum("carmen_order", CarmenOptions::Order::kAuto,
                      {{"stamp", CarmenOptions::Order::kStamp},
                       {"file", CarmenOptions::Order::kFile},
                       {"auto", CarmenOptions::Order::kAuto}},
                      "CARMEN records in stamp order, or in file order with event times held non-decreasing "
                      "(stamps that run backwards); auto: file order when the stamps run backwards by less than "
                      "2 s only (arrival times with jitter, as Intel's), else stamp order");
  out->extra = o;
}

bool IsCarmenText(const std::string& path) {
  // Text (possibly gzip-compressed): CARMEN logs start with comments or message names.
  gzFile f = gzopen(path.c_str(), "rb");
  if (!f) return false;
  char buf[256] = {0};
  const int n = gzread(f, buf, sizeof buf - 1);
  gzclose(f);
  if (n <= 0) return false;
  const std::string text(buf, n);
  for (const char* tag : {"#", "PARAM", "ODOM", "FLASER", "RLASER", "ROBOTLASER", "RAWLASER", "TRUEPOS", "SYNC"}) {
    if (text.rfind(tag, 0) == 0) return true;
  }
  return false;
}

bool IsCases(const std::string& path, const char* type) {
  std::string cases;
  return IsPlanningCasesPath(path, &cases) && cases == type;
}

// libs/drivers' own types; detect_order < 0 may name a folder, the others need a regular file.
std::deque<SourceType> DatasetTypes() {
  std::deque<SourceType> t;
  t.push_back({"astar_cases",
               "the botlab A* test cases: a folder of *_poses.txt files beside their maps, or one of them",
               [](const std::string& p) { return IsCases(p, "astar_cases"); }, -1, nullptr,
               [](const SourceOptions& o) { return std::make_unique<PlanningCasesSource>(o.path, "astar_cases"); }});
  t.push_back({"movingai", "a Moving AI .map.scen scenario file (its map beside it, or in ../../maps)",
               [](const std::string& p) { return IsCases(p, "movingai"); }, -1, nullptr,
               [](const SourceOptions& o) { return std::make_unique<PlanningCasesSource>(o.path, "movingai"); }});
  t.push_back({"map", "a map file (botlab .map, PGM + YAML, MRPT .gridmap/.simplemap, Moving AI .map): one map event",
               [](const std::string& p) { return IsMapFile(p); }, 0, nullptr,
               [](const SourceOptions& o) { return std::make_unique<MapSource>(o.path); }});
  t.push_back({"rawlog", "an MRPT rawlog (.rawlog, .rawlog.gz), both formats",
               [](const std::string& p) { return EndsWith(p, ".rawlog") || EndsWith(p, ".rawlog.gz"); }, 0, nullptr,
               [](const SourceOptions& o) { return std::make_unique<RawlogSource>(o); }});
  t.push_back({"motor_csv", "a motor calibration CSV (duty and wheel speed per channel)",
               [](const std::string& p) { return EndsWith(p, ".csv") && IsMotorSamplesFile(p); }, 0, nullptr,
               [](const SourceOptions& o) { return std::make_unique<MotorSamplesSource>(o.path); }});
  t.push_back({"carmen", "a CARMEN log, plain or gzip", IsCarmenText, 20, ParseCarmenOptions,
               [](const SourceOptions& o) { return std::make_unique<CarmenSource>(o); }});
  t.push_back({"camera",
               "camera frames: a device index, a video file or a GStreamer pipeline (OpenCV VideoCapture), or an "
               "image folder or file replayed at camera_fps",
               IsImageFileOrFolder, -1, ParseCameraSourceOptions,
               [](const SourceOptions& o) { return std::make_unique<CameraSource>(o); }});
  t[0].path_kind = SourceType::Path::kFileOrFolder;   // astar_cases: a folder, or one poses file
  t.back().path_kind = SourceType::Path::kUnchecked;  // camera: a device index or a pipeline, too
  return t;
}

}  // namespace

void RegisterDatasetSources() {
  if (FindSourceType("rawlog")) return;
  for (SourceType& t : DatasetTypes()) RegisterSourceType(std::move(t));
}

}  // namespace mbot::drivers
