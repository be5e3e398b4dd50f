// The simulated camera (libs/sim SimCamera) and the tag pose on its frames (Google Benchmark):
//  - BM_SimCameraRender: one 640 x 480 frame of an arena with three crates in view (sensor noise,
//    blur and exposure change on), time per frame;
//  - BM_TagPoseError/<range_cm>/<angle_deg>/<upright>/<blur>: a crate's tag seen from range_cm
//    (camera to tag) with the crate turned angle_deg, 20 frames each with their own noise and a
//    lateral offset up to ±5 cm; each frame through the reference detector (default settings, but
//    blur_sigma = blur / 10 px) and IPPE_SQUARE (upright 1: upright_tags, the more upright of IPPE's
//    two poses when both fit); counters
//    recall, median and worst position error of the tag's centre [cm] and of its heading [deg]
//    against the simulator's truth. Time: detection + pose per frame.
// The camera: fx = fy = 530, 640 x 480, 20 cm up, pitched 20 degrees down, 5 cm ahead of the axle
// (config/heavy_lift.ini's). Run: build/tests/mbot_sim_camera_benchmark
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "mbot/sim/sim_camera.hpp"
#include "mbot/vision/tag_observer.hpp"

namespace {

using mbot::motion::Pose2D;
using mbot::sim::SimCamera;
using mbot::sim::SimCameraOptions;
using mbot::sim::World;

SimCameraOptions Camera() {
  SimCameraOptions o;
  o.enabled = true;
  o.mount.x_m = 0.05, o.mount.z_m = 0.20, o.mount.pitch_rad = 20 * M_PI / 180;
  return o;
}

void BM_SimCameraRender(benchmark::State& st) {
  const SimCamera camera(Camera());
  const World w = World::ParseArena(
      "box -1 -1.5 2 1.5\ncrate 1 0.6 0.2 10\ncrate 2 0.9 -0.25 -30\ncrate 3 1.3 0.1 45\n", "bench.arena");
  std::mt19937_64 rng(1);
  for (auto _ : st) benchmark::DoNotOptimize(camera.Render(w, {0, 0, 0}, rng).data);
}

// The same scene without the sensor (exposure, blur, noise): what the ray casting costs.
void BM_SimCameraScene(benchmark::State& st) {
  const SimCamera camera(Camera());
  const World w = World::ParseArena(
      "box -1 -1.5 2 1.5\ncrate 1 0.6 0.2 10\ncrate 2 0.9 -0.25 -30\ncrate 3 1.3 0.1 45\n", "bench.arena");
  for (auto _ : st) benchmark::DoNotOptimize(camera.RenderScene(w, {0, 0, 0}).data);
}

double Median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

void BM_TagPoseError(benchmark::State& st) {
  const double range = st.range(0) / 100.0, angle = st.range(1) * M_PI / 180.0;
  const SimCameraOptions o = Camera();
  const SimCamera camera(o);
  mbot::vision::TagObserverOptions oo;
  oo.tag_size_m = o.tag_size_m;
  oo.mount = o.mount;
  oo.upright_tags = st.range(2) != 0;
  oo.detector.blur_sigma = st.range(3) / 10.0;
  mbot::vision::TagObserver observer(oo, camera.options().intrinsics);
  // Frames: the crate's near face `range` ahead of the camera (horizontally), offset sideways.
  struct Frame {
    cv::Mat image;
    cv::Vec3d truth;  // the tag's centre, robot frame
    double yaw;       // the face's inward normal, robot frame
  };
  std::vector<Frame> frames;
  std::mt19937_64 rng(static_cast<uint64_t>(st.range(0) * 1000 + st.range(1)));
  std::uniform_real_distribution<double> lateral(-0.05, 0.05);
  for (int k = 0; k < 20; ++k) {
    const double y = lateral(rng);
    // The face's centre at (cam_x + range, y); the crate's centre half a side behind it along its normal.
    const double fx = o.mount.x_m + range, fy = y;
    const double cx = fx + 0.05 * std::cos(angle), cy = fy + 0.05 * std::sin(angle);
    World w = World::ParseArena("box -1 -1.5 2.5 1.5\ncrate 9 " + std::to_string(cx) + " " + std::to_string(cy) + " " +
                                    std::to_string(angle * 180 / M_PI) + "\n",
                                "pose.arena");
    frames.push_back({camera.Render(w, {0, 0, 0}, rng), {fx, fy, 0.04}, angle});
  }
  std::vector<double> position_cm, heading_deg;
  int found = 0, tries = 0;
  for (auto _ : st) {
    for (const Frame& f : frames) {
      const auto tags = observer.Observe(f.image);
      ++tries;
      // The tag on the face towards the camera: the detection nearest the truth.
      const mbot::vision::ObservedTag* best = nullptr;
      for (const auto& t : tags) {
        if (!best || cv::norm(t.robot_position - f.truth) < cv::norm(best->robot_position - f.truth)) best = &t;
      }
      if (!best || best->detection.id != 9) continue;
      ++found;
      position_cm.push_back(100 * cv::norm(best->robot_position - f.truth));
      const cv::Vec3d z = o.mount.Rotation() * best->camera.R * cv::Vec3d(0, 0, 1);
      heading_deg.push_back(std::abs(std::remainder(std::atan2(z[1], z[0]) - f.yaw, 2 * M_PI)) * 180 / M_PI);
    }
  }
  st.SetItemsProcessed(tries);
  st.counters["recall"] = tries ? static_cast<double>(found) / tries : 0;
  st.counters["pos_median_cm"] = Median(position_cm);
  st.counters["pos_max_cm"] = position_cm.empty() ? NAN : *std::max_element(position_cm.begin(), position_cm.end());
  st.counters["heading_median_deg"] = Median(heading_deg);
  st.counters["heading_max_deg"] =
      heading_deg.empty() ? NAN : *std::max_element(heading_deg.begin(), heading_deg.end());
  st.counters["ms_per_frame"] =
      benchmark::Counter(static_cast<double>(tries) * 1e-3, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

BENCHMARK(BM_SimCameraRender)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SimCameraScene)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_TagPoseError)
    ->ArgsProduct({{20, 40, 60, 80, 100}, {0, 20, 40}, {1}, {0, 8}})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
