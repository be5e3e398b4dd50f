// The arena format (datasets/arenas/*.arena): walls, poses, crates and their stacks, parsed with
// line numbers in every error; a map file instead is a world of its occupied cells.
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "mbot/common/strings.hpp"
#include "mbot/drivers/map_io.hpp"
#include "mbot/sim/world.hpp"
#include "world_limits.hpp"

namespace mbot::sim {
namespace fs = std::filesystem;
using namespace world_limits;

namespace {

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

bool HasArenaExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".arena";
}

}  // namespace

World World::Load(const std::string& path) {
  World w;
  if (HasArenaExtension(path)) {
    w = ParseArena(ReadText(path), path);
  } else {
    // Names the file itself. What was never mapped is no floor: map_saver's grey 205 is unknown (a wall).
    const mapping::OccupancyGrid grid = drivers::ReadAnyMap(path, nullptr, /*saver_unknown=*/true);
    try {
      w = FromGrid(grid);
    } catch (const std::exception& e) {
      throw std::runtime_error(path + ": " + e.what());
    }
  }
  if (w.name_.empty()) w.name_ = fs::path(path).stem().string();
  return w;
}

World World::ParseArena(const std::string& text, const std::string& origin) {
  std::vector<WallSegment> walls;
  std::vector<ArenaPose> poses;
  std::vector<std::pair<Crate, int>> crates;  // with their lines, added once the walls exist
  std::optional<CrateArea> crate_area;
  std::vector<std::pair<int, int>> stacks;
  std::vector<int> stack_lines;
  int crate_area_line = 0;
  std::string name;
  double thickness = 0.02, resolution = 0.025;
  int name_line = 0, resolution_line = 0, first_wall_line = 0;

  std::istringstream in(text);
  std::string raw;
  int line_no = 0;
  auto fail = [&](const std::string& why) -> void {
    throw std::runtime_error(origin + ":" + std::to_string(line_no) + ": " + why);
  };
  auto number = [&](const std::string& stmt, const std::string& tok) {
    double v = 0;
    const auto r = std::from_chars(tok.data(), tok.data() + tok.size(), v);
    if (r.ptr != tok.data() + tok.size() || (r.ec != std::errc() && r.ec != std::errc::result_out_of_range)) {
      fail("'" + stmt + "': '" + tok + "' is not a number");
    }
    if (r.ec != std::errc() || !std::isfinite(v)) fail("'" + stmt + "': '" + tok + "' is not a finite number");
    return v;
  };
  // A heading in degrees: beyond a thousand turns it is no heading (and 1e308 × π overflows to inf).
  auto heading = [&](const std::string& stmt, const std::string& tok) {
    const double deg = number(stmt, tok);
    if (std::abs(deg) > 360000.0) fail("'" + stmt + "': heading " + tok + " deg is not a heading (|theta| <= 360000)");
    return motion::WrapAngle(deg * kPi / 180.0);
  };
  int start_line = 0;
  while (std::getline(in, raw)) {
    ++line_no;
    const auto hash = raw.find('#');
    const std::string line = Trim(hash == std::string::npos ? raw : raw.substr(0, hash));
    if (line.empty()) continue;
    std::istringstream ls(line);
    std::string stmt, tok;
    ls >> stmt;
    std::vector<std::string> args;
    while (ls >> tok) args.push_back(tok);
    auto need = [&](size_t n, const std::string& what) {
      if (args.size() != n) fail("'" + stmt + "' needs " + what + ", got " + std::to_string(args.size()));
    };

    if (stmt == "name") {
      if (name_line) fail("'name' given twice (first at line " + std::to_string(name_line) + ")");
      name = Trim(line.substr(4));
      if (name.empty()) fail("'name' needs a text");
      name_line = line_no;
    } else if (stmt == "resolution") {
      if (resolution_line) fail("'resolution' given twice (first at line " + std::to_string(resolution_line) + ")");
      need(1, "1 number");
      resolution = number(stmt, args[0]);
      if (resolution < kMinResolution || resolution > kMaxResolution) {
        fail("'resolution' " + args[0] + " out of range [" + Num(kMinResolution) + ", " + Num(kMaxResolution) + "] m");
      }
      resolution_line = line_no;
    } else if (stmt == "thickness") {
      need(1, "1 number");
      const double t = number(stmt, args[0]);
      if (t < kMinThickness || t > kMaxThickness) {
        fail("'thickness' " + args[0] + " out of range [" + Num(kMinThickness) + ", " + Num(kMaxThickness) + "] m");
      }
      if (first_wall_line && t != thickness) {
        fail("'thickness' " + args[0] + " differs from the " + Num(thickness) + " m of the walls before (line " +
             std::to_string(first_wall_line) + "); an arena has one wall thickness");
      }
      thickness = t;
    } else if (stmt == "wall" || stmt == "box") {
      need(4, "4 numbers");
      double v[4];
      for (int i = 0; i < 4; ++i) v[i] = number(stmt, args[i]);
      if (stmt == "wall") {
        if (v[0] == v[2] && v[1] == v[3]) fail("'wall' has zero length");
        walls.push_back({v[0], v[1], v[2], v[3]});
      } else {
        if (v[0] == v[2] || v[1] == v[3]) fail("'box' has zero width or height");
        const double xa = std::min(v[0], v[2]), xb = std::max(v[0], v[2]);
        const double ya = std::min(v[1], v[3]), yb = std::max(v[1], v[3]);
        walls.push_back({xa, ya, xb, ya});
        walls.push_back({xb, ya, xb, yb});
        walls.push_back({xb, yb, xa, yb});
        walls.push_back({xa, yb, xa, ya});
      }
      if (!first_wall_line) first_wall_line = line_no;
      if (walls.size() > kMaxWalls) fail("more than " + std::to_string(kMaxWalls) + " walls in one arena");
    } else if (stmt == "pose") {
      need(4, "<label> <x> <y> <theta_deg> (4 values)");
      ArenaPose p;
      p.label = args[0];
      p.pose.x = number(stmt, args[1]);
      p.pose.y = number(stmt, args[2]);
      p.pose.theta = heading(stmt, args[3]);
      if (p.label == "start") {
        if (start_line) fail("a second 'pose start' (the first is on line " + std::to_string(start_line) + ")");
        start_line = line_no;
      }
      poses.push_back(p);
    } else if (stmt == "crate") {
      if (args.size() != 4 && args.size() != 7) {
        fail("'crate' needs <id> <x> <y> <theta_deg> [<width> <depth> <height>], got " + std::to_string(args.size()));
      }
      Crate c;
      const double id = number(stmt, args[0]);
      if (id < 0 || id > 586 || id != std::floor(id)) fail("'crate' id " + args[0] + " is not a tag36h11 id (0-586)");
      c.id = static_cast<int>(id);
      c.pose = {number(stmt, args[1]), number(stmt, args[2]), heading(stmt, args[3])};
      if (args.size() == 7) {
        c.width_m = number(stmt, args[4]), c.depth_m = number(stmt, args[5]), c.height_m = number(stmt, args[6]);
      }
      for (const auto& [other, at] : crates) {
        if (other.id == c.id) fail("'crate' id " + args[0] + " given twice (first at line " + std::to_string(at) + ")");
      }
      crates.push_back({c, line_no});
    } else if (stmt == "crates_at_random") {
      if (args.size() != 3 && args.size() != 5) {
        fail("'crates_at_random' needs <count> <x> <y> [<side> <first_id>], got " + std::to_string(args.size()));
      }
      if (crate_area) fail("'crates_at_random' given twice");
      CrateArea a;
      const double count = number(stmt, args[0]);
      if (count < 1 || count > 20 || count != std::floor(count))
        fail("'crates_at_random' count " + args[0] + " not in 1-20");
      a.count = static_cast<int>(count);
      a.x = number(stmt, args[1]), a.y = number(stmt, args[2]);
      if (args.size() == 5) {
        a.side_m = number(stmt, args[3]);
        const double first = number(stmt, args[4]);
        if (!(a.side_m > 0.1 && a.side_m <= 20)) fail("'crates_at_random' side " + args[3] + " not in (0.1, 20] m");
        if (first < 0 || first + a.count - 1 > 586 || first != std::floor(first)) {
          fail("'crates_at_random' ids from " + args[4] + " leave tag36h11 (0-586)");
        }
        a.first_id = static_cast<int>(first);
      }
      crate_area = a;
      crate_area_line = line_no;
    } else if (stmt == "stack") {
      if (args.size() != 2)
        fail("'stack' needs <crate id> <id of the crate it goes on>, got " + std::to_string(args.size()));
      const double a = number(stmt, args[0]), b = number(stmt, args[1]);
      if (a < 0 || b < 0 || a > 586 || b > 586 || a != std::floor(a) || b != std::floor(b) || a == b)
        fail("'stack' needs two different tag36h11 ids (0-586), got " + args[0] + " " + args[1]);
      stacks.emplace_back(static_cast<int>(a), static_cast<int>(b));
      stack_lines.push_back(line_no);
    } else {
      fail("unknown statement '" + stmt +
           "' (known: name, resolution, thickness, wall, box, pose, crate, crates_at_random, stack)");
    }
  }
  if (walls.empty()) throw std::runtime_error(origin + ": no walls (an arena needs at least one 'wall' or 'box')");
  // Every crate a stack names exists, none is stacked twice, and no stack leads back to itself.
  auto crate_exists = [&](int id) {
    if (crate_area && id >= crate_area->first_id && id < crate_area->first_id + crate_area->count) return true;
    return std::any_of(crates.begin(), crates.end(), [&](const auto& c) { return c.first.id == id; });
  };
  for (size_t k = 0; k < stacks.size(); ++k) {
    line_no = stack_lines[k];
    const auto [top, bottom] = stacks[k];
    for (const int id : {top, bottom}) {
      if (!crate_exists(id))
        fail("'stack' names crate " + std::to_string(id) + ", which no 'crate' or 'crates_at_random' places");
    }
    for (size_t e = 0; e < k; ++e) {
      if (stacks[e].first == top) {
        fail("'stack': crate " + std::to_string(top) + " is stacked twice (first at line " +
             std::to_string(stack_lines[e]) + ")");
      }
    }
    std::string chain = std::to_string(top);
    for (int at = bottom, steps = 0;; ++steps) {
      chain += " on " + std::to_string(at);
      if (at == top) fail("'stack' makes a cycle: " + chain);
      const auto next = std::find_if(stacks.begin(), stacks.begin() + static_cast<std::ptrdiff_t>(k),
                                     [&](const auto& st) { return st.first == at; });
      if (next == stacks.begin() + static_cast<std::ptrdiff_t>(k) || steps > static_cast<int>(stacks.size())) break;
      at = next->second;
    }
  }
  if (crate_area) {
    for (const auto& [c, at] : crates) {
      if (c.id >= crate_area->first_id && c.id < crate_area->first_id + crate_area->count) {
        line_no = at;
        fail("'crate' id " + std::to_string(c.id) + " is also one of the ids of 'crates_at_random' (line " +
             std::to_string(crate_area_line) + ")");
      }
    }
  }
  World w;
  try {
    w = FromSegments(std::move(walls), thickness, resolution);
  } catch (const std::exception& e) {
    throw std::runtime_error(origin + ": " + e.what() +
                             (resolution_line ? " (resolution on line " + std::to_string(resolution_line) + ")" : ""));
  }
  w.name_ = name.empty() ? fs::path(origin).stem().string() : name;
  w.poses_ = std::move(poses);
  w.crate_area_ = crate_area;
  w.stacks_ = std::move(stacks);
  // Crates stand in the room: in the start's free space, or, without a start, off the free space
  // around the walls (the true map's margin).
  if (!crates.empty() || crate_area) {
    const auto& g = w.truth();
    const std::vector<motion::Pose2D> starts = w.PosesLabelled("start");
    std::vector<uint8_t> outside;
    bool room_is_start = false;
    if (!starts.empty()) {
      int sx, sy;
      g.WorldToCell(starts.front().x, starts.front().y, &sx, &sy);
      if (g.IsInside(sx, sy) && g.at(sx, sy) < 0) {
        outside = ReachableFreeMask(w, starts.front());
        room_is_start = true;
      }
    }
    if (!room_is_start)
      outside = ReachableFreeMask(w, {g.origin_x() + 0.5 * g.resolution(), g.origin_y() + 0.5 * g.resolution(), 0.0});
    auto in_room = [&](double x, double y) {
      int i, j;
      g.WorldToCell(x, y, &i, &j);
      if (!g.IsInside(i, j)) return false;
      if (g.at(i, j) >= 0) return true;  // on a wall: AddCrate says it overlaps one
      const bool reached = outside[static_cast<size_t>(j) * g.width() + i] != 0;
      return room_is_start ? reached : !reached;
    };
    const std::string room = room_is_start ? "the free space of 'pose start'" : "the walls";
    for (const auto& [c, at] : crates) {
      if (!in_room(c.pose.x, c.pose.y)) {
        throw std::runtime_error(origin + ":" + std::to_string(at) + ": crate " + std::to_string(c.id) + " at (" +
                                 Num(c.pose.x) + ", " + Num(c.pose.y) + ") is outside " + room);
      }
    }
    if (crate_area && !in_room(crate_area->x, crate_area->y)) {
      throw std::runtime_error(origin + ":" + std::to_string(crate_area_line) + ": 'crates_at_random' centre (" +
                               Num(crate_area->x) + ", " + Num(crate_area->y) + ") is outside " + room);
    }
  }
  for (const auto& [crate, at] : crates) {
    try {
      w.AddCrate(crate);
    } catch (const std::exception& e) {
      throw std::runtime_error(origin + ":" + std::to_string(at) + ": " + e.what());
    }
  }
  return w;
}

}  // namespace mbot::sim
