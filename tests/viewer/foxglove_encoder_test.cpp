// The viewer's encoder: events to Foxglove's JSON messages (the schemas themselves are checked by
// Foxglove's npm package in tests/viewer/foxglove_client.mjs).
#include "mbot/viewer/foxglove_encoder.hpp"

#include <cmath>
#include <memory>

#include <gtest/gtest.h>

#include "mbot/viewer/server.hpp"

namespace mbot::viewer {
namespace {

msgs::Event MakeEvent(msgs::EventKind kind, int64_t t_us, msgs::Payload payload) {
  msgs::Event e;
  e.kind = kind;
  e.t_us = t_us;
  e.payload = std::move(payload);
  return e;
}

TEST(FoxgloveEncoder, Base64MatchesRfc4648) {
  EXPECT_EQ(Base64("", 0), "");
  EXPECT_EQ(Base64("f", 1), "Zg==");
  EXPECT_EQ(Base64("fo", 2), "Zm8=");
  EXPECT_EQ(Base64("foo", 3), "Zm9v");
  EXPECT_EQ(Base64("foobar", 6), "Zm9vYmFy");
}

TEST(FoxgloveEncoder, TimeSplitsSecondsAndNanoseconds) {
  const nlohmann::json t = TimeJson(12'345'678);
  EXPECT_EQ(t["sec"], 12);
  EXPECT_EQ(t["nsec"], 345'678'000);
}

TEST(FoxgloveEncoder, OccupancyIsRosPercent) {
  EXPECT_EQ(OccupancyPercent(0), -1);
  EXPECT_LT(OccupancyPercent(-127), 5);
  EXPECT_GT(OccupancyPercent(127), 95);
  EXPECT_EQ(OccupancyPercent(1) >= 50, true);
}

TEST(FoxgloveEncoder, MapIsAGridOfTheKnownCells) {
  auto grid = std::make_shared<msgs::OccupancyGrid>(200, 100, 0.05, -5.0, -2.5, 0);
  grid->at(100, 50) = 100;  // one occupied cell; the rest unknown
  FoxgloveEncoder enc;
  const auto out =
      enc.Encode(MakeEvent(msgs::EventKind::kMap, 1'000'000, std::shared_ptr<const msgs::OccupancyGrid>(grid)));
  ASSERT_EQ(out.size(), 1u);
  const nlohmann::json& m = out[0].payload;
  EXPECT_EQ(out[0].topic, "/map");
  EXPECT_EQ(m["frame_id"], "map");
  EXPECT_DOUBLE_EQ(m["cell_size"]["x"].get<double>(), 0.05);
  const int cols = m["column_count"];
  EXPECT_LT(cols, 200);  // cropped to what is known
  EXPECT_EQ(m["row_stride"], cols);
  EXPECT_EQ(m["fields"][0]["type"], 2);  // INT8
  // The occupied cell is where it was: its centre (0.025, 0.025) lies in the grid's cell.
  const double ox = m["pose"]["position"]["x"], oy = m["pose"]["position"]["y"];
  EXPECT_LE(ox, 0.0);
  EXPECT_LE(oy, 0.0);
}

TEST(FoxgloveEncoder, ScanBeamsAreEvenlySpacedInAngleOrder) {
  msgs::LidarScan scan;
  scan.ranges_m = {2.0f, 1.0f, 0.0f, 3.0f};
  scan.angles_rad = {0.3f, 0.0f, 0.1f, 0.2f};  // out of order, as an RPLidar's wrap gives them
  scan.sensor_pose = {0.05, 0.0, M_PI};
  FoxgloveEncoder enc;
  const auto out = enc.Encode(MakeEvent(msgs::EventKind::kLidar, 5, scan));
  ASSERT_EQ(out.size(), 1u);
  const nlohmann::json& m = out[0].payload;
  EXPECT_NEAR(m["start_angle"].get<double>(), 0.0, 1e-6);
  EXPECT_NEAR(m["end_angle"].get<double>(), 0.3, 1e-6);
  const std::vector<double> ranges = m["ranges"];
  ASSERT_EQ(ranges.size(), 4u);
  EXPECT_DOUBLE_EQ(ranges[0], 1.0);
  EXPECT_DOUBLE_EQ(ranges[1], 0.0);  // no return
  EXPECT_DOUBLE_EQ(ranges[2], 3.0);
  EXPECT_DOUBLE_EQ(ranges[3], 2.0);
}

TEST(FoxgloveEncoder, TransformsCloseMapOdomBaseLidar) {
  FoxgloveEncoder enc;
  msgs::LidarScan scan;
  scan.ranges_m = {1.0f};
  scan.angles_rad = {0.0f};
  scan.sensor_pose = {0.1, 0.0, M_PI};
  enc.Encode(MakeEvent(msgs::EventKind::kLidar, 1, scan));
  enc.Encode(MakeEvent(msgs::EventKind::kPoseEstimate, 2, msgs::Pose2D{1.0, 2.0, M_PI / 2}));
  const auto out = enc.Encode(MakeEvent(msgs::EventKind::kOdometry, 3, msgs::Pose2D{0.5, 0.0, 0.0}));
  ASSERT_EQ(out.size(), 2u);  // /odom and /tf
  const nlohmann::json& tf = out[1].payload["transforms"];
  ASSERT_EQ(tf.size(), 3u);
  EXPECT_EQ(tf[0]["parent_frame_id"], "map");
  EXPECT_EQ(tf[0]["child_frame_id"], "odom");
  EXPECT_EQ(tf[2]["child_frame_id"], "lidar");
  // map→odom ⊕ odom→base = the estimate.
  const msgs::Pose2D map_odom{
      tf[0]["translation"]["x"], tf[0]["translation"]["y"],
      2 * std::atan2(tf[0]["rotation"]["z"].get<double>(), tf[0]["rotation"]["w"].get<double>())};
  const msgs::Pose2D base = map_odom.Compose({0.5, 0.0, 0.0});
  EXPECT_NEAR(base.x, 1.0, 1e-9);
  EXPECT_NEAR(base.y, 2.0, 1e-9);
  EXPECT_NEAR(tf[2]["translation"]["x"].get<double>(), 0.1, 1e-9);
}

TEST(FoxgloveEncoder, DistancesAreCentimetresOfTheRoomyPart) {
  // A 10 x 8 grid at 0.1 m whose room is the block x 2..5, y 3..4: the message holds that block.
  auto d = std::make_shared<msgs::DistanceGrid>();
  d->width = 10, d->height = 8, d->resolution_m = 0.1, d->origin_x = -1.0, d->origin_y = 2.0;
  d->distance_m.assign(80, 0.0f);
  for (int y = 3; y <= 4; ++y)
    for (int x = 2; x <= 5; ++x) d->distance_m[y * 10 + x] = 0.1f * float(x);
  d->distance_m[4 * 10 + 5] = 9.0f;  // past 2.55 m: capped
  FoxgloveEncoder enc;
  const auto out = enc.Encode(
      MakeEvent(msgs::EventKind::kObstacleDistance, 2'000'000, std::shared_ptr<const msgs::DistanceGrid>(d)));
  ASSERT_EQ(out.size(), 1u);
  const nlohmann::json& m = out[0].payload;
  EXPECT_EQ(out[0].topic, "/obstacle_distance");
  EXPECT_EQ(m["column_count"], 4);
  EXPECT_EQ(m["fields"][0]["name"], "distance_cm");
  EXPECT_EQ(m["fields"][0]["type"], 1);  // UINT8
  EXPECT_NEAR(m["pose"]["position"]["x"].get<double>(), -1.0 + 0.2, 1e-9);
  EXPECT_NEAR(m["pose"]["position"]["y"].get<double>(), 2.0 + 0.3, 1e-9);
  // 8 bytes in base64: 12 characters; first row 20, 30, 40, 50 cm; the last cell 255.
  const std::string data = m["data"];
  const uint8_t expected[8] = {20, 30, 40, 50, 20, 30, 40, 255};
  EXPECT_EQ(data, Base64(expected, 8));
}

TEST(FoxgloveEncoder, FrontiersAndScore) {
  msgs::Frontiers f;
  f.cell_size_m = 0.05;
  f.regions.push_back({1.0, 2.0, {{0.975, 2.0, 0}, {1.025, 2.0, 0}}});
  FoxgloveEncoder enc;
  auto out = enc.Encode(MakeEvent(msgs::EventKind::kFrontiers, 1, f));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].topic, "/scene");
  const nlohmann::json& e = out[0].payload["entities"][0];
  EXPECT_EQ(e["id"], "frontiers");
  EXPECT_EQ(e["cubes"].size(), 2u);
  EXPECT_EQ(e["spheres"].size(), 1u);
  EXPECT_DOUBLE_EQ(e["spheres"][0]["pose"]["position"]["x"].get<double>(), 1.0);

  msgs::ScoreStatus s{"Maze Explorer", 250, 300, 1, 42.5, {{"map quality", "coverage 99 %", 100, 100}}};
  out = enc.Encode(MakeEvent(msgs::EventKind::kScore, 2, s));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].topic, "/score");
  EXPECT_EQ(out[0].payload["points"], 250);
  EXPECT_EQ(out[0].payload["items"][0]["max_points"], 100);
}

TEST(FoxgloveEncoder, EveryChannelHasASchema) {
  for (const ChannelSpec& c : Channels()) {
    EXPECT_FALSE(c.schema.empty()) << c.topic;
    EXPECT_TRUE(nlohmann::json::accept(c.schema)) << c.topic;
  }
}

TEST(FoxgloveServer, RefusesUnsafeOptions) {
  ServerOptions o;
  o.address = "0.0.0.0";
  o.port = 0;
  o.http_port = -1;
  FoxgloveServer open_to_all(o, Channels());
  EXPECT_THROW(open_to_all.Start(), std::runtime_error);  // no token on a non-loopback address
  ServerOptions c;
  c.port = 0;
  c.http_port = -1;
  c.control = true;
  FoxgloveServer control(c, Channels());
  EXPECT_THROW(control.Start(), std::runtime_error);  // control without a token
  EXPECT_TRUE(IsLoopback("127.0.0.1"));
  EXPECT_FALSE(IsLoopback("192.168.1.5"));
  EXPECT_EQ(NewToken().size(), 32u);
}

}  // namespace
}  // namespace mbot::viewer
