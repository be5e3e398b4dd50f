// The simulated camera: tags on crates come out where the true projection puts them, so the
// detector finds them and the pose from their corners matches the simulator's truth; nearer
// surfaces hide farther ones.
#include "mbot/sim/sim_camera.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "mbot/sim/sim_robot.hpp"
#include "mbot/vision/tag_observer.hpp"

namespace mbot::sim {
namespace {

using motion::Pose2D;

SimCameraOptions Camera() {
  SimCameraOptions o;
  o.enabled = true;
  o.mount.x_m = 0.05, o.mount.z_m = 0.20, o.mount.pitch_rad = 20 * M_PI / 180;
  return o;
}

vision::TagObserverOptions Observer(const SimCameraOptions& c) {
  vision::TagObserverOptions o;
  o.tag_size_m = c.tag_size_m;
  o.mount = c.mount;
  return o;
}

// The centre of the tag on the crate's face that looks towards `from` (world frame).
cv::Vec3d TagCentre(const Crate& c, const Pose2D& from) {
  const double a = std::atan2(from.y - c.pose.y, from.x - c.pose.x) - c.pose.theta;
  const double k = std::round(a / (0.5 * M_PI));
  const double n = c.pose.theta + k * 0.5 * M_PI;
  const double half = static_cast<long>(std::abs(k)) % 2 == 0 ? 0.5 * c.width_m : 0.5 * c.depth_m;
  return {c.pose.x + half * std::cos(n), c.pose.y + half * std::sin(n), c.z_m + 0.5 * c.height_m};
}

TEST(SimCamera, TagPosesMatchTheTruth) {
  const SimCameraOptions o = Camera();
  const SimCamera camera(o);
  vision::TagObserver observer(Observer(o), camera.options().intrinsics);  // fx = fy = 530, centred
  std::mt19937_64 rng(5);
  for (double range : {0.3, 0.5, 0.8}) {
    for (double turn_deg : {0.0, 25.0}) {
      World w = World::ParseArena(
          "box -2 -2 3 2\ncrate 17 " + std::to_string(range + 0.05) + " 0.02 " + std::to_string(turn_deg) + "\n",
          "camera.arena");
      const Pose2D robot{-0.05, 0.0, 0.0};  // the camera at the origin
      const cv::Mat frame = camera.Render(w, robot, rng);
      ASSERT_EQ(frame.cols, 640);
      ASSERT_EQ(frame.rows, 480);
      std::vector<vision::ObservedTag> tags = observer.Observe(frame);
      // A turned crate shows a second face (its side, at a grazing angle): the same id.
      ASSERT_GE(tags.size(), 1u) << "range " << range << " turn " << turn_deg;
      ASSERT_LE(tags.size(), 2u);
      const cv::Vec3d truth = TagCentre(w.crates()[0], robot) - cv::Vec3d(robot.x, robot.y, 0.0);
      std::sort(tags.begin(), tags.end(), [&](const auto& a, const auto& b) {
        return cv::norm(a.robot_position - truth) < cv::norm(b.robot_position - truth);
      });
      EXPECT_EQ(tags[0].detection.id, 17);
      // The tag's centre in the robot frame against the truth.
      const double err = cv::norm(tags[0].robot_position - truth);
      EXPECT_LT(err, 0.01) << "range " << range << " turn " << turn_deg;
      // Its heading: the tag's z axis (into the tag) in the world against the face's inward normal.
      cv::Matx33d Rw;
      cv::Vec3d tw;
      camera.CameraPose(robot, &Rw, &tw);
      const cv::Vec3d z = Rw * tags[0].camera.R * cv::Vec3d(0, 0, 1);
      const double yaw = std::atan2(z[1], z[0]) * 180 / M_PI;
      EXPECT_NEAR(yaw, turn_deg, 2.0) << "range " << range;
      // Upright. Its tilt is the worst-conditioned angle of a small tag seen face on (the pose's
      // two IPPE solutions draw close): at 0.8 m the tag is 36 pixels wide.
      EXPECT_NEAR(z[2], 0.0, range < 0.7 ? 0.04 : 0.1) << "range " << range << " turn " << turn_deg;
    }
  }
}

TEST(SimCamera, NearerSurfacesHideFartherOnes) {
  const SimCameraOptions o = Camera();
  const SimCamera camera(o);
  vision::TagObserver observer(Observer(o), camera.options().intrinsics);
  std::mt19937_64 rng(6);
  const Pose2D robot{-0.05, 0.0, 0.0};
  auto seen = [&](const std::string& arena) {
    World w = World::ParseArena("box -2 -2 3 2\n" + arena, "camera.arena");
    std::vector<int> ids;
    for (const auto& t : observer.Observe(camera.Render(w, robot, rng))) ids.push_back(t.detection.id);
    return ids;
  };
  EXPECT_EQ(seen("crate 3 0.8 0 0\n"), std::vector<int>{3});
  // A crate 20 cm high (the camera's height) in front hides crate 3; a common one is looked over.
  EXPECT_EQ(seen("crate 3 0.8 0 0\ncrate 4 0.5 0 0 0.1 0.1 0.2\n"), std::vector<int>{4});
  EXPECT_EQ(seen("crate 3 0.8 0 0\ncrate 4 0.4 0 0\n"), (std::vector<int>{3, 4}));
  EXPECT_EQ(seen("crate 3 0.8 0 0\nwall 0.5 -0.3 0.5 0.3\n"), std::vector<int>{});
  EXPECT_EQ(seen("crate 3 0.8 0 0\ncrate 4 0.8 0.3 0\n"), (std::vector<int>{3, 4}));
}

TEST(SimCamera, ACrateOnTheTinesHidesTheFloorAheadAndTheSensorAddsNoise) {
  SimCameraOptions o = Camera();
  const SimCamera camera(o);
  World w = World::ParseArena("box -2 -2 3 2\ncrate 3 0.17 0 0\n", "camera.arena");
  const Pose2D robot{0.0, 0.0, 0.0};
  const cv::Mat floor_only = camera.RenderScene(World::ParseArena("box -2 -2 3 2\n", "e.arena"), robot);
  Crate lifted = w.crates()[0];
  lifted.carried = true;
  lifted.z_m = 0.06;
  w.SetCrate(0, lifted);
  const cv::Mat carrying = camera.RenderScene(w, robot);
  // The bottom rows (floor just ahead) are now the crate's near face: brighter than the floor.
  EXPECT_LT(cv::mean(floor_only.rowRange(440, 480))[0], 100);
  EXPECT_GT(cv::mean(carrying.rowRange(440, 480))[0], 140);
  // The sensor: two frames of the same scene differ by its noise, not by much on average.
  std::mt19937_64 rng(1);
  o.exposure_change = 0;
  const SimCamera noisy(o);
  cv::Mat a = noisy.Render(w, robot, rng), b = noisy.Render(w, robot, rng), diff;
  cv::absdiff(a, b, diff);
  EXPECT_GT(cv::mean(diff)[0], 1.0);
  EXPECT_LT(cv::mean(diff)[0], 4.0);
}

}  // namespace
}  // namespace mbot::sim

namespace mbot::sim {
namespace {

// The simulated robot publishes its camera's frames at the camera's rate, on CAMERA.
TEST(SimCamera, SimRobotPublishesFramesAtItsRate) {
  World w = World::ParseArena("box -2 -2 3 2\ncrate 11 0.6 0 0\n", "camera.arena");
  SimRobotOptions o;
  o.camera = Camera();
  o.camera.rate_hz = 10;
  SimRobot robot(w, o, {0, 0, 0}, 2);
  std::vector<Event> events;
  robot.AdvanceTo(1'000'000, &events);
  std::vector<int64_t> times;
  for (const Event& e : events) {
    if (e.kind != EventKind::kCameraFrame) continue;
    EXPECT_EQ(e.channel, "CAMERA");
    const auto& f = std::get<msgs::CameraFrame>(e.payload);
    ASSERT_EQ(f.width, 640);
    ASSERT_EQ(f.height, 480);
    ASSERT_TRUE(f.pixels && f.pixels->size() == 640u * 480u);
    times.push_back(e.t_us);
  }
  ASSERT_EQ(times.size(), 10u);
  EXPECT_EQ(times.front(), 100'000);
  EXPECT_EQ(times.back(), 1'000'000);
}

}  // namespace
}  // namespace mbot::sim
