#include "mbot/drivers/map_io.hpp"

#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/poses/CPose3DPDF.h>
#include <mrpt/serialization/CArchive.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <octomap/OcTree.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/config.hpp"
#include "mbot/common/files.hpp"
#include "mbot/common/log.hpp"
#include "mbot/common/strings.hpp"
#include "mbot/msgs/scan_renderer.hpp"
#include "mrpt_read.hpp"
#include "mrpt_scan.hpp"

namespace fs = std::filesystem;

namespace mbot::drivers {

namespace {

std::string ShortestDouble(double v) {
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

[[noreturn]] void Fail(const std::string& path, const std::string& why) { throw std::runtime_error(path + ": " + why); }

// A header's claim of `w` × `h` cells, each at least `bytes_per_cell` bytes in the file: within
// kMaxMapCells and what the file can hold. `where` names the field ("line 1: width x height").
void CheckDeclaredCells(const std::string& path, const std::string& where, long long w, long long h,
                        double bytes_per_cell) {
  if (w <= 0 || h <= 0) Fail(path, where + " " + std::to_string(w) + " x " + std::to_string(h) + " is not a size");
  if (w > kMaxMapCells / h) {
    Fail(path, where + " " + std::to_string(w) + " x " + std::to_string(h) + " exceeds the limit of " +
                   std::to_string(kMaxMapCells) + " cells");
  }
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  if (!ec && static_cast<double>(w) * h * bytes_per_cell > static_cast<double>(size) + 1.0) {
    Fail(path, where + " " + std::to_string(w) + " x " + std::to_string(h) + " cells, but the file holds only " +
                   std::to_string(size) + " bytes");
  }
}

// Origins and resolutions a map may have (see map_io.hpp).
void CheckFrame(const std::string& path, const std::string& where, double ox, double oy, double res) {
  if (!std::isfinite(ox) || !std::isfinite(oy) || std::abs(ox) > 1e6 || std::abs(oy) > 1e6) {
    Fail(path, where + " origin (" + ShortestDouble(ox) + ", " + ShortestDouble(oy) + ") is not within ±1e6 m");
  }
  if (!(res >= 1e-4 && res <= 100.0))
    Fail(path, where + " resolution " + ShortestDouble(res) + " is not in [1e-4, 100] m");
}

// A map image's declared size (PGM P2 text or P5 binary, or PNG), checked before OpenCV allocates it.
void CheckImageHeader(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char png[24] = {};
  if (in.read(reinterpret_cast<char*>(png), sizeof png) && png[0] == 0x89 && png[1] == 'P' && png[2] == 'N' &&
      png[3] == 'G') {
    auto be32 = [&](int at) {
      return (long long)png[at] << 24 | (long long)png[at + 1] << 16 | (long long)png[at + 2] << 8 | png[at + 3];
    };
    // A PNG compresses well, so only the cell limit applies (not the file's size).
    CheckDeclaredCells(path, "PNG header: width x height", be32(16), be32(20), 0.0);
    return;
  }
  in.clear();
  in.seekg(0);
  std::string magic;
  if (!(in >> magic) || (magic != "P5" && magic != "P2")) return;  // another image format: OpenCV's to judge
  long long v[3];
  for (long long& x : v) {
    while (in >> std::ws && in.peek() == '#') in.ignore(1 << 20, '\n');
    if (!(in >> x)) Fail(path, "PGM header: expected width, height and maximum value");
  }
  CheckDeclaredCells(path, "PGM header: width x height", v[0], v[1], magic == "P5" ? 1.0 : 2.0);
}

}  // namespace

msgs::OccupancyGrid ReadBotlabMap(const std::string& path) {
  std::ifstream in(path);
  if (!in) Fail(path, "cannot open map");
  double ox, oy, res;
  long long w, h;
  if (!(in >> ox >> oy >> w >> h >> res))
    Fail(path, "line 1: expected 'origin_x origin_y width height meters_per_cell'");
  CheckDeclaredCells(path, "line 1: width x height", w, h, 2.0);  // a value and a separator per cell
  CheckFrame(path, "line 1:", ox, oy, res);
  msgs::OccupancyGrid grid(static_cast<int>(w), static_cast<int>(h), res, ox, oy);
  for (long long y = 0; y < h; ++y) {
    for (long long x = 0; x < w; ++x) {
      int v;
      if (!(in >> v)) {
        Fail(path, "line " + std::to_string(y + 2) + ": expected " + std::to_string(w) +
                       " cells, file ends or has a non-number at cell " + std::to_string(x));
      }
      if (v < -128 || v > 127)
        Fail(path, "line " + std::to_string(y + 2) + ": cell value " + std::to_string(v) + " outside int8");
      grid.at(static_cast<int>(x), static_cast<int>(y)) = static_cast<int8_t>(std::max(v, -127));
    }
  }
  std::string extra;
  if (in >> extra) Fail(path, "more cells than width x height (" + std::to_string(w * h) + ")");
  return grid;
}

void WriteBotlabMap(const msgs::OccupancyGrid& g, const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << ShortestDouble(g.origin_x()) << ' ' << ShortestDouble(g.origin_y()) << ' ' << g.width() << ' ' << g.height()
        << ' ' << ShortestDouble(g.resolution()) << '\n';
    std::string row;
    for (int y = 0; y < g.height(); ++y) {
      row.clear();
      for (int x = 0; x < g.width(); ++x) {
        row += std::to_string(int(g.at(x, y)));
        row += ' ';
      }
      row.back() = '\n';
      out << row;
    }
  });
}

msgs::OccupancyGrid ReadRosMap(const std::string& yaml_path, bool saver_unknown) {
  std::ifstream in(yaml_path);
  if (!in) Fail(yaml_path, "cannot open map YAML");
  std::string image;
  double res = 0, ox = 0, oy = 0, yaw = 0, occ_th = 0.65, free_th = 0.196;
  bool negate = false, have_res = false, have_origin = false;
  std::string mode = "trinary";
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto hash = line.find('#');
    if (hash != std::string::npos) line = line.substr(0, hash);
    const auto colon = line.find(':');
    if (Trim(line).empty()) continue;
    if (colon == std::string::npos) Fail(yaml_path, "line " + std::to_string(line_no) + ": expected 'key: value'");
    const std::string key = Trim(line.substr(0, colon));
    std::string value = Trim(line.substr(colon + 1));
    const std::string where = "line " + std::to_string(line_no) + ": " + key + ": ";
    try {
      if (key == "image") {
        if (value.size() >= 2 && (value[0] == '"' || value[0] == '\'')) value = value.substr(1, value.size() - 2);
        image = value;
      } else if (key == "resolution") {
        res = std::stod(value);
        have_res = true;
      } else if (key == "origin") {
        std::string v = value;
        std::replace(v.begin(), v.end(), '[', ' ');
        std::replace(v.begin(), v.end(), ']', ' ');
        std::replace(v.begin(), v.end(), ',', ' ');
        std::istringstream s(v);
        if (!(s >> ox >> oy >> yaw)) Fail(yaml_path, where + "expected [x, y, yaw]");
        have_origin = true;
      } else if (key == "negate") {
        negate = std::stoi(value) != 0;
      } else if (key == "occupied_thresh") {
        occ_th = std::stod(value);
      } else if (key == "free_thresh") {
        free_th = std::stod(value);
      } else if (key == "mode") {
        mode = value;
      }
    } catch (const std::logic_error&) {
      Fail(yaml_path, where + "bad value '" + value + "'");
    }
  }
  if (image.empty()) Fail(yaml_path, "missing key 'image'");
  if (!have_res || !(res > 0)) Fail(yaml_path, "missing or bad 'resolution'");
  if (!have_origin) Fail(yaml_path, "missing 'origin'");
  if (std::abs(yaw) > 1e-9)
    Fail(yaml_path, "origin yaw " + ShortestDouble(yaw) + " is not supported (only axis-aligned maps)");
  if (mode != "trinary" && mode != "scale") Fail(yaml_path, "mode '" + mode + "' is not supported (trinary, scale)");
  CheckFrame(yaml_path, "", ox, oy, res);
  const fs::path img_path = fs::path(image).is_absolute() ? fs::path(image) : fs::path(yaml_path).parent_path() / image;
  CheckImageHeader(img_path.string());
  RequireReadableFile(img_path.string());
  cv::Mat img;
  try {
    img = cv::imread(img_path.string(), cv::IMREAD_GRAYSCALE);
  } catch (const cv::Exception& e) {  // e.g. an image larger than OpenCV's CV_IO_MAX_IMAGE_PIXELS
    Fail(img_path.string(), "cannot read map image (named in " + yaml_path + "): " + e.err);
  }
  if (img.empty()) Fail(img_path.string(), "cannot read map image (named in " + yaml_path + ")");
  CheckDeclaredCells(img_path.string(), "image width x height", img.cols, img.rows, 0.0);
  msgs::OccupancyGrid grid(img.cols, img.rows, res, ox, oy);
  const bool saver_grey = saver_unknown && mode == "trinary" && !negate;  // map_saver writes negate: 0
  for (int r = 0; r < img.rows; ++r) {
    const uint8_t* row = img.ptr<uint8_t>(r);
    const int y = img.rows - 1 - r;
    for (int x = 0; x < img.cols; ++x) {
      const int p = negate ? 255 - row[x] : row[x];
      const double occ = (255.0 - p) / 255.0;
      int8_t v = 0;
      if (saver_grey && row[x] == 205)
        v = 0;  // map_saver's unknown
      else if (occ > occ_th)
        v = static_cast<int8_t>(std::clamp(127 - p, 1, 127));
      else if (occ < free_th)
        v = static_cast<int8_t>(std::clamp(127 - p, -127, -1));
      grid.at(x, y) = v;
    }
  }
  return grid;
}

void WriteRosMap(const msgs::OccupancyGrid& g, const std::string& yaml_path) {
  const fs::path yaml(yaml_path);
  const fs::path pgm = fs::path(yaml).replace_extension(".pgm");
  cv::Mat img(g.height(), g.width(), CV_8UC1);
  for (int y = 0; y < g.height(); ++y) {
    uint8_t* row = img.ptr<uint8_t>(g.height() - 1 - y);
    for (int x = 0; x < g.width(); ++x) row[x] = static_cast<uint8_t>(127 - int(g.at(x, y)));
  }
  const std::string tmp = TempPathFor(pgm.string());
  if (!cv::imwrite(tmp, img)) Fail(pgm.string(), "cannot write image");
  CommitFile(tmp, pgm.string());
  WriteFileAtomically(yaml_path, [&](std::ostream& out) {
    out << "image: " << pgm.filename().string() << "\n"
        << "resolution: " << ShortestDouble(g.resolution()) << "\n"
        << "origin: [" << ShortestDouble(g.origin_x()) << ", " << ShortestDouble(g.origin_y()) << ", 0.0]\n"
        << "negate: 0\n"
        << "# pixel = 127 - log-odds: these thresholds split occupied / free at log-odds 0\n"
        << "occupied_thresh: 0.504\n"  // log-odds >= 1 (pixel <= 126) is occupied
        << "free_thresh: 0.5\n"        // log-odds <= -1 (pixel >= 128) is free
        << "mode: trinary\n";
  });
}

msgs::OccupancyGrid ReadMrptGridmap(const std::string& path) {
  mrpt::maps::COccupancyGridMap2D m;
  ReadMrptFile(path, "MRPT gridmap", [&] {
    mrpt::io::CFileGZInputStream f(path);
    auto arch = mrpt::serialization::archiveFrom(f);
    auto obj = arch.ReadObject();
    auto grid = std::dynamic_pointer_cast<mrpt::maps::COccupancyGridMap2D>(obj);
    if (!grid) Fail(path, std::string("holds a ") + obj->GetRuntimeClass()->className + ", not a COccupancyGridMap2D");
    m = *grid;
  });
  CheckDeclaredCells(path, "grid size_x x size_y", m.getSizeX(), m.getSizeY(), 0.0);
  CheckFrame(path, "grid", m.getXMin(), m.getYMin(), m.getResolution());
  msgs::OccupancyGrid out(static_cast<int>(m.getSizeX()), static_cast<int>(m.getSizeY()), m.getResolution(),
                          m.getXMin(), m.getYMin());
  for (int y = 0; y < out.height(); ++y) {
    for (int x = 0; x < out.width(); ++x) {
      const double p_occ = std::clamp(1.0 - double(m.getCell(x, y)), 1e-6, 1.0 - 1e-6);
      out.at(x, y) = static_cast<int8_t>(std::clamp(std::lround(20.0 * std::log(p_occ / (1.0 - p_occ))), -127L, 127L));
    }
  }
  return out;
}

msgs::OccupancyGrid ReadMrptSimplemap(const std::string& path, double resolution_m) {
  mrpt::maps::CSimpleMap sm;
  ReadMrptFile(path, "MRPT simplemap", [&] {
    if (!sm.loadFromFile(path)) Fail(path, "cannot read MRPT simplemap");
  });
  // The keyframes' scans, each at its keyframe's pose, rendered by libs/mapping (msgs::ScanRenderer).
  std::vector<msgs::PosedScan> posed;
  msgs::Pose2D centre;  // the grid starts around the first keyframe
  for (size_t k = 0; k < sm.size(); ++k) {
    if (const auto pair = sm.getAsPair(k); pair.pose) {
      centre = {pair.pose->getMeanVal().x(), pair.pose->getMeanVal().y(), 0};
      break;
    }
  }
  for (size_t k = 0; k < sm.size(); ++k) {
    const auto pair = sm.getAsPair(k);
    if (!pair.pose || !pair.sf) continue;
    const mrpt::poses::CPose3D mean = pair.pose->getMeanVal();
    const msgs::Pose2D robot{mean.x(), mean.y(), mean.yaw()};
    for (const auto& obs : *pair.sf) {
      auto mrpt_scan = std::dynamic_pointer_cast<mrpt::obs::CObservation2DRangeScan>(obs);
      if (mrpt_scan) posed.push_back({robot, FromMrptScan(*mrpt_scan)});
    }
  }
  const size_t scans = posed.size();
  if (scans == 0)
    Fail(path, "holds no 2D range scans to build a grid from (" + std::to_string(sm.size()) + " keyframes)");
  const msgs::ScanRenderer* render = msgs::GetScanRenderer();
  if (!render) Fail(path, "a simplemap is rendered by libs/mapping, whose renderer this program did not register");
  msgs::RenderedGrid r = (*render)(posed, resolution_m, centre);
  if (r.rejected_scans == static_cast<int>(scans)) {
    Fail(path, "none of its " + std::to_string(scans) + " scans could be inserted (non-finite poses or ranges " +
                   "that would grow the grid past " + std::to_string(kMaxMapCells) + " cells)");
  }
  if (r.rejected_scans > 0) {
    mbot::log::Warn(path + ": " + std::to_string(r.rejected_scans) + " of " + std::to_string(scans) +
                    " scans left out (non-finite poses or ranges that would grow the grid past " +
                    std::to_string(kMaxMapCells) + " cells)");
  }
  return std::move(r.grid);
}

msgs::OccupancyGrid ReadMovingAiMap(const std::string& path) {
  std::ifstream in(path);
  if (!in) Fail(path, "cannot open map");
  std::string line, word;
  int w = -1, h = -1, line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    std::istringstream s(Trim(line));
    s >> word;
    if (word == "type") continue;
    if (word == "height")
      s >> h;
    else if (word == "width")
      s >> w;
    else if (word == "map")
      break;
    else
      Fail(path, "line " + std::to_string(line_no) + ": unexpected header '" + Trim(line) + "'");
  }
  if (w <= 0 || h <= 0) Fail(path, "missing width/height header");
  CheckDeclaredCells(path, "header width x height", w, h, 1.0);
  msgs::OccupancyGrid grid(w, h, 1.0, 0.0, 0.0);
  for (int r = 0; r < h; ++r) {
    if (!std::getline(in, line)) Fail(path, "ends after " + std::to_string(r) + " of " + std::to_string(h) + " rows");
    ++line_no;
    line = Trim(line);  // CRLF files
    if (static_cast<int>(line.size()) != w) {
      Fail(path, "line " + std::to_string(line_no) + ": row has " + std::to_string(line.size()) + " cells, expected " +
                     std::to_string(w));
    }
    for (int x = 0; x < w; ++x) {
      const char c = line[x];
      grid.at(x, h - 1 - r) = (c == '.' || c == 'G' || c == 'S') ? int8_t(-127) : int8_t(127);
    }
  }
  return grid;
}

void WriteMapPng(const msgs::OccupancyGrid& g, const std::string& path) {
  cv::Mat img(g.height(), g.width(), CV_8UC1);
  for (int y = 0; y < g.height(); ++y) {
    uint8_t* row = img.ptr<uint8_t>(g.height() - 1 - y);
    for (int x = 0; x < g.width(); ++x) row[x] = static_cast<uint8_t>(127 - int(g.at(x, y)));
  }
  const std::string tmp = TempPathFor(path);
  if (!cv::imwrite(tmp, img)) Fail(path, "cannot write PNG");
  CommitFile(tmp, path);
}

void WriteMapPngWithOverlays(const msgs::OccupancyGrid& g, const std::vector<MapOverlay>& overlays, int scale,
                             const std::string& path) {
  scale = std::max(1, scale);
  cv::Mat gray(g.height(), g.width(), CV_8UC1);
  for (int y = 0; y < g.height(); ++y) {
    uint8_t* row = gray.ptr<uint8_t>(g.height() - 1 - y);
    for (int x = 0; x < g.width(); ++x) row[x] = static_cast<uint8_t>(127 - int(g.at(x, y)));
  }
  cv::Mat img;
  cv::cvtColor(gray, img, cv::COLOR_GRAY2BGR);
  if (scale > 1) cv::resize(img, img, cv::Size(), scale, scale, cv::INTER_NEAREST);
  auto pixel = [&](const msgs::Pose2D& p) {
    const double px = (p.x - g.origin_x()) / g.resolution() * scale;
    const double py = (g.height() - (p.y - g.origin_y()) / g.resolution()) * scale;
    return cv::Point(static_cast<int>(std::lround(px)), static_cast<int>(std::lround(py)));
  };
  int legend_y = 14;
  for (const MapOverlay& o : overlays) {
    const cv::Scalar colour(o.b, o.g, o.r);
    if (o.points) {
      const int r = std::max(1, o.point_radius_px);
      for (const msgs::Pose2D& p : o.poses) cv::circle(img, pixel(p), r, colour, r > 2 ? 2 : cv::FILLED, cv::LINE_AA);
    } else if (o.poses.size() > 1) {
      std::vector<cv::Point> line;
      line.reserve(o.poses.size());
      for (const msgs::Pose2D& p : o.poses) line.push_back(pixel(p));
      cv::polylines(img, line, false, colour, 1, cv::LINE_AA);
    }
    if (!o.label.empty()) {
      cv::line(img, cv::Point(6, legend_y - 4), cv::Point(22, legend_y - 4), colour, 2);
      cv::putText(img, o.label, cv::Point(26, legend_y), cv::FONT_HERSHEY_SIMPLEX, 0.4, colour, 1, cv::LINE_AA);
      legend_y += 14;
    }
  }
  const std::string tmp = TempPathFor(path);
  if (!cv::imwrite(tmp, img)) Fail(path, "cannot write PNG");
  CommitFile(tmp, path);
}

void WriteOctomap(const msgs::OccupancyGrid& g, double wall_height_m, const std::string& path) {
  const double res = g.resolution();
  octomap::OcTree tree(res);
  const int layers = std::max(1, static_cast<int>(std::ceil(wall_height_m / res)));
  for (int y = 0; y < g.height(); ++y) {
    for (int x = 0; x < g.width(); ++x) {
      const int8_t v = g.at(x, y);
      if (v == 0) continue;
      double wx, wy;
      g.CellToWorld(x, y, &wx, &wy);
      if (v > 0) {
        for (int k = 0; k < layers; ++k) tree.updateNode(octomap::point3d(wx, wy, (k + 0.5) * res), true, true);
      } else {
        tree.updateNode(octomap::point3d(wx, wy, 0.5 * res), false, true);
      }
    }
  }
  tree.updateInnerOccupancy();
  mbot::WriteFileAtomically(path, [&](std::ostream& out) {
    if (!tree.writeBinary(out)) throw std::runtime_error(path + ": cannot serialise the OctoMap");
  });
}

bool IsMapFile(const std::string& path) {
  for (const char* ext : {".yaml", ".yml", ".gridmap", ".gridmap.gz", ".simplemap", ".simplemap.gz", ".map"}) {
    if (EndsWith(path, ext)) return true;
  }
  return false;
}

msgs::OccupancyGrid ReadAnyMap(const std::string& path, std::string* format, bool saver_unknown) {
  RequireReadableFile(path);
  auto set = [&](const char* f) {
    if (format) *format = f;
  };
  if (EndsWith(path, ".yaml") || EndsWith(path, ".yml")) {
    set("ROS map_server (PGM + YAML)");
    return ReadRosMap(path, saver_unknown);
  }
  if (EndsWith(path, ".gridmap") || EndsWith(path, ".gridmap.gz")) {
    set("MRPT gridmap");
    return ReadMrptGridmap(path);
  }
  if (EndsWith(path, ".simplemap") || EndsWith(path, ".simplemap.gz")) {
    set("MRPT simplemap (scans inserted at 0.05 m)");
    return ReadMrptSimplemap(path);
  }
  if (EndsWith(path, ".map")) {
    std::ifstream in(path);
    std::string first;
    in >> first;
    if (first == "type") {
      set("Moving AI map");
      return ReadMovingAiMap(path);
    }
    set("botlab .map");
    return ReadBotlabMap(path);
  }
  Fail(path, "not a known map format (.map, .yaml, .gridmap, .gridmap.gz, .simplemap, .simplemap.gz)");
}

void WriteSlamCheckpoint(const std::string& ini_path, const msgs::OccupancyGrid& map, const SlamCheckpoint& c) {
  const fs::path ini(ini_path);
  const fs::path map_path = fs::path(ini).replace_extension(".map");
  WriteBotlabMap(map, map_path.string());
  WriteFileAtomically(ini_path, [&](std::ostream& out) {
    out << "# mbot_nav SLAM checkpoint: resume with --set slam.resume_from=" << ini_path << "\n"
        << "[checkpoint]\n"
        << "map = " << map_path.filename().string() << "\n"
        << "pose = " << ShortestDouble(c.pose.x) << ", " << ShortestDouble(c.pose.y) << ", "
        << ShortestDouble(c.pose.theta * 180.0 / M_PI) << "\n"
        << "odometry = " << ShortestDouble(c.odometry.x) << ", " << ShortestDouble(c.odometry.y) << ", "
        << ShortestDouble(c.odometry.theta * 180.0 / M_PI) << "\n"
        << "t_s = " << ShortestDouble(c.t_s) << "\n"
        << "scans = " << c.scans << "\n";
  });
}

SlamCheckpoint ReadSlamCheckpoint(const std::string& ini_path) {
  RequireReadableFile(ini_path);
  const config::Config cfg = config::Config::Load(ini_path);
  config::Section s = cfg.GetSection("checkpoint");
  if (!cfg.HasSection("checkpoint")) Fail(ini_path, "no [checkpoint] section (not a SLAM checkpoint)");
  SlamCheckpoint c;
  const std::string map = s.GetString("map", "", "the checkpoint's map, beside it");
  if (map.empty()) s.Fail("map", "required");
  c.map_path = (fs::path(ini_path).parent_path() / map).string();
  const config::PoseValue p = s.GetPose("pose", {}, "the estimate at the last scan");
  c.pose = {p.x_m, p.y_m, p.theta_rad};
  const config::PoseValue o = s.GetPose("odometry", {}, "the robot's odometry at the last scan");
  c.odometry = {o.x_m, o.y_m, o.theta_rad};
  c.t_s = s.GetDouble("t_s", 0.0, "the last scan's time [s]", -1e12, 1e12);
  c.scans = s.GetInt("scans", 0, "scans processed", 0, 1LL << 50);
  return c;
}

}  // namespace mbot::drivers
