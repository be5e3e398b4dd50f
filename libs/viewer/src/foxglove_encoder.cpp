#include "mbot/viewer/foxglove_encoder.hpp"

#include <algorithm>
#include <cmath>

#include "viewer_assets.hpp"

namespace mbot::viewer {

using nlohmann::json;

namespace {

// The project's own message types: what the mission and SLAM say about themselves.
constexpr const char* kMissionSchema = R"({"title":"mbot.MissionStatus","type":"object",
"properties":{"timestamp":{"type":"object","properties":{"sec":{"type":"integer"},"nsec":{"type":"integer"}}},
"state":{"type":"string"},"detail":{"type":"string"}},"required":["timestamp","state","detail"]})";
constexpr const char* kSlamSchema = R"({"title":"mbot.SlamStatus","type":"object",
"properties":{"timestamp":{"type":"object","properties":{"sec":{"type":"integer"},"nsec":{"type":"integer"}}},
"state":{"type":"string"},"mode":{"type":"string"},"spread_m":{"type":"number"},
"mapping_on":{"type":"boolean"},"localization_on":{"type":"boolean"}},
"required":["timestamp","state","mode","spread_m","mapping_on","localization_on"]})";

constexpr const char* kScoreSchema = R"({"title":"mbot.Score","type":"object",
"properties":{"timestamp":{"type":"object","properties":{"sec":{"type":"integer"},"nsec":{"type":"integer"}}},
"event":{"type":"string"},"points":{"type":"integer"},"max_points":{"type":"integer"},
"collisions":{"type":"integer"},"elapsed_s":{"type":"number"},
"items":{"type":"array","items":{"type":"object","properties":{"name":{"type":"string"},"detail":{"type":"string"},
"points":{"type":"integer"},"max_points":{"type":"integer"}},"required":["name","detail","points","max_points"]}}},
"required":["timestamp","event","points","max_points","collisions","elapsed_s","items"]})";

constexpr const char* kStampSchema = R"({"title":"mbot.SentStamp","type":"object",
"properties":{"timestamp":{"type":"object","properties":{"sec":{"type":"integer"},"nsec":{"type":"integer"}}},
"topic":{"type":"string"},"offered_wall_us":{"type":"integer"}},"required":["timestamp","topic","offered_wall_us"]})";

std::string Schema(const char* file) {
  const Asset* a = FindAsset(std::string("schemas/") + file);
  return a ? std::string(a->data, a->size) : std::string();
}

json Vec3(double x, double y, double z) { return {{"x", x}, {"y", y}, {"z", z}}; }
json Quat(double theta) { return {{"x", 0.0}, {"y", 0.0}, {"z", std::sin(theta / 2)}, {"w", std::cos(theta / 2)}}; }
json Color(double r, double g, double b, double a) { return {{"r", r}, {"g", g}, {"b", b}, {"a", a}}; }

// A SceneEntity with every array the schema requires, empty.
json Entity(const std::string& id, const std::string& frame, int64_t t_us) {
  return {{"timestamp", TimeJson(t_us)},
          {"frame_id", frame},
          {"id", id},
          {"lifetime", {{"sec", 0}, {"nsec", 0}}},
          {"frame_locked", false},
          {"metadata", json::array()},
          {"arrows", json::array()},
          {"cubes", json::array()},
          {"spheres", json::array()},
          {"cylinders", json::array()},
          {"lines", json::array()},
          {"triangles", json::array()},
          {"texts", json::array()},
          {"models", json::array()}};
}

// A foxglove.Grid of one byte-wide field (`type`: Foxglove's NumericType, 1 UINT8, 2 INT8), rows
// from the origin (the lower-left corner of cell 0) up.
json GridJson(int64_t t_us, const std::string& frame, double origin_x, double origin_y, int columns, double resolution,
              const char* field, int type, const void* cells, size_t size) {
  return {{"timestamp", TimeJson(t_us)},
          {"frame_id", frame},
          {"pose", PoseJson({origin_x, origin_y, 0.0}, 0.0)},
          {"column_count", columns},
          {"cell_size", {{"x", resolution}, {"y", resolution}}},
          {"row_stride", columns},
          {"cell_stride", 1},
          {"fields", json::array({{{"name", field}, {"offset", 0}, {"type", type}}})},
          {"data", Base64(cells, size)}};
}

json Transform(const std::string& parent, const std::string& child, const msgs::Pose2D& p, double z, int64_t t_us) {
  return {{"timestamp", TimeJson(t_us)},
          {"parent_frame_id", parent},
          {"child_frame_id", child},
          {"translation", Vec3(p.x, p.y, z)},
          {"rotation", Quat(p.theta)}};
}

}  // namespace

const std::vector<ChannelSpec>& Channels() {
  static const std::vector<ChannelSpec> channels = {
      {"/map", "foxglove.Grid", Schema("Grid.json")},
      {"/scan", "foxglove.LaserScan", Schema("LaserScan.json")},
      {"/tf", "foxglove.FrameTransforms", Schema("FrameTransforms.json")},
      {"/pose", "foxglove.PoseInFrame", Schema("PoseInFrame.json")},
      {"/odom", "foxglove.PoseInFrame", Schema("PoseInFrame.json")},
      {"/particles", "foxglove.PosesInFrame", Schema("PosesInFrame.json")},
      {"/path", "foxglove.PosesInFrame", Schema("PosesInFrame.json")},
      {"/scene", "foxglove.SceneUpdate", Schema("SceneUpdate.json")},
      {"/log", "foxglove.Log", Schema("Log.json")},
      {"/mission", "mbot.MissionStatus", kMissionSchema},
      {"/slam_status", "mbot.SlamStatus", kSlamSchema},
      {"/obstacle_distance", "foxglove.Grid", Schema("Grid.json")},
      {"/score", "mbot.Score", kScoreSchema},
      {"/scan_stamp", "mbot.SentStamp", kStampSchema},
  };
  return channels;
}

json TimeJson(int64_t t_us) {
  if (t_us < 0) t_us = 0;
  return {{"sec", t_us / 1000000}, {"nsec", (t_us % 1000000) * 1000}};
}

json PoseJson(const msgs::Pose2D& p, double z) {
  return {{"position", Vec3(p.x, p.y, z)}, {"orientation", Quat(p.theta)}};
}

std::string Base64(const void* data, size_t size) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* b = static_cast<const uint8_t*>(data);
  std::string out;
  out.reserve((size + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < size; i += 3) {
    const uint32_t v = (uint32_t{b[i]} << 16) | (uint32_t{b[i + 1]} << 8) | b[i + 2];
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (i < size) {
    uint32_t v = uint32_t{b[i]} << 16;
    if (i + 1 < size) v |= uint32_t{b[i + 1]} << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += i + 1 < size ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

int8_t OccupancyPercent(int8_t log_odds) {
  if (log_odds == 0) return -1;
  // Log-odds in [-127, 127] to a probability in percent; the sign decides free or occupied.
  const double p = 1.0 / (1.0 + std::exp(-log_odds / 16.0));
  return static_cast<int8_t>(std::clamp(std::lround(p * 100.0), 0L, 100L));
}

FoxgloveEncoder::FoxgloveEncoder(Frames frames, double robot_radius_m)
    : frames_(std::move(frames)), robot_radius_m_(robot_radius_m) {}

std::vector<FoxgloveMessage> FoxgloveEncoder::Encode(const msgs::Event& event) {
  out_.clear();
  msgs::Visit(event, *this);
  return std::move(out_);
}

void FoxgloveEncoder::Add(const std::string& topic, int64_t t_us, json payload) {
  out_.push_back({topic, t_us, std::move(payload)});
}

void FoxgloveEncoder::AddTransforms(int64_t t_us) {
  json transforms = json::array();
  // map → odom closes the loop between the estimate and dead reckoning; without odometry the
  // estimate is the robot's pose in the map (odom = map).
  const msgs::Pose2D odom = odom_.value_or(msgs::Pose2D{});
  const msgs::Pose2D estimate = estimate_.value_or(odom);
  transforms.push_back(Transform(frames_.map, frames_.odom, estimate.Compose(odom.Inverse()), 0.0, t_us));
  transforms.push_back(Transform(frames_.odom, frames_.base, odom, 0.0, t_us));
  transforms.push_back(Transform(frames_.base, frames_.lidar, lidar_mount_, 0.0, t_us));
  Add("/tf", t_us, {{"transforms", std::move(transforms)}});
}

bool FoxgloveEncoder::Lidar(const msgs::Event& e, const msgs::LidarScan& scan) {
  lidar_mount_ = scan.sensor_pose;
  if (scan.ranges_m.empty()) return true;
  // foxglove.LaserScan spaces its beams evenly from start_angle to end_angle: the beams go into
  // bins of the scan's mean spacing, in angle order; a bin no beam fell in has range 0 (no return).
  const size_t n = scan.ranges_m.size();
  std::vector<size_t> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = i;
  const auto angle = [&](size_t i) { return i < scan.angles_rad.size() ? double(scan.angles_rad[i]) : 0.0; };
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return angle(a) < angle(b); });
  const double start = angle(order.front()), end = angle(order.back());
  std::vector<double> ranges(n, 0.0), intensities;
  const double step = n > 1 ? (end - start) / double(n - 1) : 0.0;
  for (size_t k = 0; k < n; ++k) {
    const size_t i = order[k];
    const size_t bin = step > 0 ? std::min(n - 1, size_t(std::lround((angle(i) - start) / step))) : k;
    const float r = scan.ranges_m[i];
    if (std::isfinite(r) && r > 0) ranges[bin] = r;
  }
  if (scan.intensities.size() == n) {
    intensities.resize(n);
    for (size_t k = 0; k < n; ++k) intensities[k] = scan.intensities[order[k]];
  }
  Add("/scan", e.t_us,
      {{"timestamp", TimeJson(e.t_us)},
       {"frame_id", frames_.lidar},
       {"pose", PoseJson({}, 0.0)},
       {"start_angle", start},
       {"end_angle", end},
       {"ranges", std::move(ranges)},
       {"intensities", std::move(intensities)}});
  return true;
}

bool FoxgloveEncoder::Pose(const msgs::Event& e, const msgs::Pose2D& pose) {
  switch (e.kind) {
    case msgs::EventKind::kOdometry:
      odom_ = pose;
      Add("/odom", e.t_us, {{"timestamp", TimeJson(e.t_us)}, {"frame_id", frames_.odom}, {"pose", PoseJson(pose, 0)}});
      AddTransforms(e.t_us);
      return true;
    case msgs::EventKind::kPoseEstimate: {
      estimate_ = pose;
      Add("/pose", e.t_us, {{"timestamp", TimeJson(e.t_us)}, {"frame_id", frames_.map}, {"pose", PoseJson(pose, 0)}});
      if (!odom_) AddTransforms(e.t_us);
      // The robot's footprint, in its own frame.
      json robot = Entity("robot", frames_.base, e.t_us);
      robot["frame_locked"] = true;
      robot["cylinders"].push_back({{"pose", PoseJson({}, 0.05)},
                                    {"size", Vec3(2 * robot_radius_m_, 2 * robot_radius_m_, 0.1)},
                                    {"bottom_scale", 1.0},
                                    {"top_scale", 1.0},
                                    {"color", Color(0.1, 0.4, 0.9, 0.8)}});
      robot["arrows"].push_back({{"pose", PoseJson({}, 0.11)},
                                 {"shaft_length", robot_radius_m_},
                                 {"shaft_diameter", 0.02},
                                 {"head_length", 0.05},
                                 {"head_diameter", 0.05},
                                 {"color", Color(1, 1, 1, 1)}});
      Add("/scene", e.t_us, {{"deletions", json::array()}, {"entities", json::array({std::move(robot)})}});
      return true;
    }
    case msgs::EventKind::kCollision: {
      Add("/log", e.t_us,
          {{"timestamp", TimeJson(e.t_us)},
           {"level", 3},
           {"message", "collision at (" + std::to_string(pose.x) + ", " + std::to_string(pose.y) + ")"},
           {"name", "simulator"},
           {"file", ""},
           {"line", 0}});
      return true;
    }
    default: return false;
  }
}

bool FoxgloveEncoder::Map(const msgs::Event& e, const msgs::OccupancyGrid& full) {
  // SLAM's grid starts large and mostly unknown; what was seen (and a margin) is what a viewer needs.
  const msgs::OccupancyGrid grid = msgs::CropToKnown(full, 0.5);
  std::vector<int8_t> cells(grid.cells().size());
  std::transform(grid.cells().begin(), grid.cells().end(), cells.begin(), OccupancyPercent);
  Add("/map", e.t_us,
      GridJson(e.t_us, frames_.map, grid.origin_x(), grid.origin_y(), grid.width(), grid.resolution(), "occupancy", 2,
               cells.data(), cells.size()));  // INT8
  return true;
}

bool FoxgloveEncoder::PathPoses(const msgs::Event& e, const msgs::Path& path) {
  json poses = json::array();
  for (const msgs::Pose2D& p : path.poses) poses.push_back(PoseJson(p, 0.02));
  Add("/path", e.t_us, {{"timestamp", TimeJson(e.t_us)}, {"frame_id", frames_.map}, {"poses", std::move(poses)}});
  if (!path.poses.empty()) {
    json goal = Entity("goal", frames_.map, e.t_us);
    goal["spheres"].push_back({{"pose", PoseJson(path.poses.back(), 0.05)},
                               {"size", Vec3(0.08, 0.08, 0.08)},
                               {"color", Color(0.1, 0.8, 0.2, 0.9)}});
    Add("/scene", e.t_us, {{"deletions", json::array()}, {"entities", json::array({std::move(goal)})}});
  }
  return true;
}

bool FoxgloveEncoder::Slam(const msgs::Event& e, const msgs::SlamStatus& status) {
  Add("/slam_status", e.t_us,
      {{"timestamp", TimeJson(e.t_us)},
       {"state", msgs::ToString(status.state)},
       {"mode", msgs::ToString(status.mode)},
       {"spread_m", status.spread_m},
       {"mapping_on", status.mapping_on},
       {"localization_on", status.localization_on}});
  return true;
}

bool FoxgloveEncoder::Mission(const msgs::Event& e, const msgs::MissionStatus& status) {
  Add("/mission", e.t_us,
      {{"timestamp", TimeJson(e.t_us)}, {"state", msgs::ToString(status.state)}, {"detail", status.detail}});
  if (status.state == msgs::MissionState::kFailed) {
    Add("/log", e.t_us,
        {{"timestamp", TimeJson(e.t_us)},
         {"level", 4},
         {"message", "mission failed: " + status.detail},
         {"name", "mission"},
         {"file", ""},
         {"line", 0}});
  }
  return true;
}

bool FoxgloveEncoder::ParticleSet(const msgs::Event& e, const msgs::Particles& particles) {
  json poses = json::array();
  for (const msgs::Pose2D& p : particles.poses) poses.push_back(PoseJson(p, 0.01));
  Add("/particles", e.t_us, {{"timestamp", TimeJson(e.t_us)}, {"frame_id", frames_.map}, {"poses", std::move(poses)}});
  return true;
}

bool FoxgloveEncoder::Tags(const msgs::Event& e, const msgs::TagSightings& tags) {
  // Tags as the camera sees them, in the camera's frame (x right, y down, z forward: OpenCV's).
  json entity = Entity("tags", "camera", e.t_us);
  entity["lifetime"] = {{"sec", 0}, {"nsec", 500000000}};
  for (const msgs::TagSighting& t : tags.tags) {
    json pose = {{"position", Vec3(t.x_m, t.y_m, t.z_m)},
                 {"orientation", {{"x", t.qx}, {"y", t.qy}, {"z", t.qz}, {"w", t.qw}}}};
    entity["cubes"].push_back({{"pose", pose}, {"size", Vec3(0.054, 0.054, 0.005)}, {"color", Color(1, 0.6, 0, 0.9)}});
    entity["texts"].push_back({{"pose", pose},
                               {"billboard", true},
                               {"font_size", 12.0},
                               {"scale_invariant", true},
                               {"color", Color(1, 1, 1, 1)},
                               {"text", "tag " + std::to_string(t.id)}});
  }
  Add("/scene", e.t_us, {{"deletions", json::array()}, {"entities", json::array({std::move(entity)})}});
  return true;
}

bool FoxgloveEncoder::Crates(const msgs::Event& e, const msgs::CrateStates& crates) {
  json entity = Entity("crates", frames_.map, e.t_us);
  for (const msgs::CrateState& c : crates.crates) {
    const double side = 0.1;
    entity["cubes"].push_back({{"pose", PoseJson(c.pose, c.z_m + side / 2)},
                               {"size", Vec3(side, side, side)},
                               {"color", c.fell ? Color(0.9, 0.1, 0.1, 0.9) : Color(0.7, 0.5, 0.2, 0.9)}});
  }
  Add("/scene", e.t_us, {{"deletions", json::array()}, {"entities", json::array({std::move(entity)})}});
  return true;
}

bool FoxgloveEncoder::FrontierSet(const msgs::Event& e, const msgs::Frontiers& frontiers) {
  // Each region's cells as flat orange tiles and its centroid as a sphere; an empty set clears them.
  json entity = Entity("frontiers", frames_.map, e.t_us);
  const double side = frontiers.cell_size_m;
  for (const msgs::FrontierRegion& r : frontiers.regions) {
    for (const msgs::Pose2D& c : r.cells) {
      entity["cubes"].push_back(
          {{"pose", PoseJson(c, 0.005)}, {"size", Vec3(side, side, 0.01)}, {"color", Color(0.95, 0.55, 0.0, 0.8)}});
    }
    entity["spheres"].push_back({{"pose", PoseJson({r.x, r.y, 0.0}, 0.03)},
                                 {"size", Vec3(0.06, 0.06, 0.06)},
                                 {"color", Color(0.85, 0.3, 0.0, 0.9)}});
  }
  Add("/scene", e.t_us, {{"deletions", json::array()}, {"entities", json::array({std::move(entity)})}});
  return true;
}

bool FoxgloveEncoder::Distances(const msgs::Event& e, const msgs::DistanceGrid& d) {
  if (d.width <= 0 || d.height <= 0 || d.distance_m.size() != size_t(d.width) * size_t(d.height)) return false;
  // Only the part with room in it (cells away from obstacles and unknown space), and centimetres
  // in one byte: the planner's clearances are well under 2.55 m.
  int x0 = d.width, y0 = d.height, x1 = -1, y1 = -1;
  for (int y = 0; y < d.height; ++y) {
    for (int x = 0; x < d.width; ++x) {
      if (d.distance_m[size_t(y) * d.width + x] > 0)
        x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
  }
  if (x1 < 0) x0 = y0 = 0, x1 = y1 = 0;  // no room anywhere: one cell
  const int w = x1 - x0 + 1, h = y1 - y0 + 1;
  std::vector<uint8_t> cm(size_t(w) * size_t(h));
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const float m = d.distance_m[size_t(y + y0) * d.width + (x + x0)];
      cm[size_t(y) * w + x] =
          static_cast<uint8_t>(std::isfinite(m) ? std::clamp(std::lround(m * 100.0), 0L, 255L) : 255);
    }
  }
  Add("/obstacle_distance", e.t_us,
      GridJson(e.t_us, frames_.map, d.origin_x + x0 * d.resolution_m, d.origin_y + y0 * d.resolution_m, w,
               d.resolution_m, "distance_cm", 1, cm.data(), cm.size()));  // UINT8
  return true;
}

bool FoxgloveEncoder::Score(const msgs::Event& e, const msgs::ScoreStatus& score) {
  json items = json::array();
  for (const msgs::ScoreItem& i : score.items) {
    items.push_back({{"name", i.name}, {"detail", i.detail}, {"points", i.points}, {"max_points", i.max_points}});
  }
  Add("/score", e.t_us,
      {{"timestamp", TimeJson(e.t_us)},
       {"event", score.event},
       {"points", score.points},
       {"max_points", score.max_points},
       {"collisions", score.collisions},
       {"elapsed_s", score.elapsed_s},
       {"items", std::move(items)}});
  return true;
}

}  // namespace mbot::viewer
