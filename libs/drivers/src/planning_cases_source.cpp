#include "planning_cases_source.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "mbot/common/strings.hpp"
#include "mbot/drivers/map_io.hpp"

namespace mbot::drivers {

using namespace msgs;  // the event vocabulary
namespace fs = std::filesystem;
namespace {

[[noreturn]] void Fail(const std::string& path, int line, const std::string& what) {
  throw std::runtime_error(path + (line > 0 ? ":" + std::to_string(line) : std::string()) + ": " + what);
}

// botlab: first line N, then N lines "start_x start_y goal_x goal_y should_exist".
void ReadBotlabCases(const std::string& poses_path, std::vector<Event>* out) {
  const std::string stem = fs::path(poses_path).filename().string();
  const std::string name = stem.substr(0, stem.size() - std::string("_poses.txt").size());
  const std::string map_path = (fs::path(poses_path).parent_path() / (name + ".map")).string();
  if (!fs::is_regular_file(map_path)) Fail(poses_path, 0, "its map " + map_path + " does not exist");
  auto grid = std::make_shared<const msgs::OccupancyGrid>(ReadBotlabMap(map_path));
  out->push_back(Event{0, 0, name, EventKind::kMap, grid});
  std::ifstream in(poses_path);
  if (!in) Fail(poses_path, 0, "cannot open");
  std::string line;
  int line_no = 0, declared = -1, read = 0;
  while (std::getline(in, line)) {
    ++line_no;
    line = Trim(line);
    if (line.empty()) continue;
    std::istringstream s(line);
    if (declared < 0) {
      if (!(s >> declared) || declared < 0)
        Fail(poses_path, line_no, "expected the number of cases, got '" + line + "'");
      continue;
    }
    PlanRequest r;
    int should = 0;
    std::string extra;
    if (!(s >> r.start.x >> r.start.y >> r.goal.x >> r.goal.y >> should) || (s >> extra) ||
        (should != 0 && should != 1)) {
      Fail(poses_path, line_no, "expected 'start_x start_y goal_x goal_y should_exist(0/1)', got '" + line + "'");
    }
    r.index = read++;
    r.expect_path = should;
    out->push_back(Event{0, 0, name, EventKind::kPlanRequest, r});
  }
  if (declared < 0) Fail(poses_path, 0, "empty file");
  if (read != declared) {
    Fail(poses_path, line_no, "declares " + std::to_string(declared) + " cases but holds " + std::to_string(read));
  }
}

// Moving AI: "version 1", then "bucket map width height sx sy gx gy optimal" (tab separated),
// (0, 0) top-left. The map column is relative to the benchmark root (or a bare name).
void ReadMovingAiScenarios(const std::string& scen_path, std::vector<Event>* out) {
  std::ifstream in(scen_path);
  if (!in) Fail(scen_path, 0, "cannot open");
  std::string line, map_rel;
  int line_no = 0;
  std::shared_ptr<const msgs::OccupancyGrid> grid;
  std::string channel;
  int index = 0;
  while (std::getline(in, line)) {
    ++line_no;
    line = Trim(line);
    if (line.empty()) continue;
    if (line_no == 1 && line.rfind("version", 0) == 0) continue;
    std::istringstream s(line);
    PlanRequest r;
    std::string map_name;
    int w, h, sx, sy, gx, gy;
    if (!(s >> r.bucket >> map_name >> w >> h >> sx >> sy >> gx >> gy >> r.optimal_length_m)) {
      Fail(scen_path, line_no,
           "expected 'bucket map width height start_x start_y goal_x goal_y optimal', got '" + line + "'");
    }
    if (!grid) {
      // Tried in each folder from the scenario's upwards: the path as written, the bare file name,
      // and maps/<the scenario's folder name>/<file> (the benchmark's own layout).
      const fs::path dir = fs::path(scen_path).parent_path();
      const fs::path file = fs::path(map_name).filename();
      std::string found;
      for (fs::path d = dir;; d = d.parent_path()) {
        for (const fs::path& candidate : {d / map_name, d / file, d / "maps" / dir.filename() / file}) {
          if (found.empty() && fs::is_regular_file(candidate)) found = candidate.string();
        }
        if (!found.empty() || d == d.parent_path() || d.empty()) break;
      }
      if (found.empty()) Fail(scen_path, line_no, "map '" + map_name + "' not found beside the file or above it");
      grid = std::make_shared<const msgs::OccupancyGrid>(ReadMovingAiMap(found));
      map_rel = map_name;
      channel = fs::path(map_name).filename().string();
      out->push_back(Event{0, 0, channel, EventKind::kMap, grid});
    } else if (map_name != map_rel) {
      Fail(scen_path, line_no, "names map '" + map_name + "' but the file started with '" + map_rel + "'");
    }
    if (w != grid->width() || h != grid->height()) {
      Fail(scen_path, line_no,
           "map size " + std::to_string(w) + "x" + std::to_string(h) + " differs from the map's " +
               std::to_string(grid->width()) + "x" + std::to_string(grid->height()));
    }
    for (auto [x, y] : {std::pair{sx, sy}, std::pair{gx, gy}}) {
      if (x < 0 || y < 0 || x >= w || y >= h) Fail(scen_path, line_no, "a position lies outside the map");
    }
    // Moving AI row y is grid row h - 1 - y (ReadMovingAiMap keeps +y up); 1 m cells.
    r.start = msgs::Pose2D{sx + 0.5, (h - 1 - sy) + 0.5, 0.0};
    r.goal = msgs::Pose2D{gx + 0.5, (h - 1 - gy) + 0.5, 0.0};
    r.index = index++;
    out->push_back(Event{0, 0, channel, EventKind::kPlanRequest, r});
  }
  if (!grid) Fail(scen_path, 0, "holds no scenario");
}

}  // namespace

bool IsPlanningCasesPath(const std::string& path, std::string* format) {
  std::string f;
  if (EndsWith(path, ".scen")) {
    f = "movingai";
  } else if (EndsWith(path, "_poses.txt")) {
    f = "astar_cases";
  } else if (fs::is_directory(path)) {
    for (const auto& e : fs::directory_iterator(path)) {
      if (EndsWith(e.path().filename().string(), "_poses.txt")) f = "astar_cases";
    }
  }
  if (format) *format = f;
  return !f.empty();
}

PlanningCasesSource::PlanningCasesSource(const std::string& path, const std::string& format) : format_(format) {
  if (format == "movingai") {
    ReadMovingAiScenarios(path, &events_);
  } else if (format == "astar_cases") {
    if (fs::is_directory(path)) {
      std::vector<std::string> files;
      for (const auto& e : fs::directory_iterator(path)) {
        if (EndsWith(e.path().filename().string(), "_poses.txt")) files.push_back(e.path().string());
      }
      if (files.empty()) Fail(path, 0, "folder holds no *_poses.txt file");
      std::sort(files.begin(), files.end());
      for (const std::string& f : files) ReadBotlabCases(f, &events_);
    } else {
      ReadBotlabCases(path, &events_);
    }
  } else {
    throw std::invalid_argument("PlanningCasesSource: unknown format " + format);
  }
  for (const Event& e : events_) {
    ChannelInfo& info = channels_[e.channel];
    info.type = format_ == "movingai" ? "Moving AI map + scenarios" : "botlab map + A* cases";
    info.kind = EventKind::kPlanRequest;
  }
}

std::optional<Event> PlanningCasesSource::Next() {
  if (next_ >= events_.size()) return std::nullopt;
  return std::move(events_[next_++]);
}

double PlanningCasesSource::Progress() const {
  return events_.empty() ? 1.0 : static_cast<double>(next_) / events_.size();
}

}  // namespace mbot::drivers
