// AprilTag detection benchmarks (Google Benchmark), the reference detector (libs/vision,
// AprilRobotics 3.3) beside OpenCV's own AprilTag 36h11 dictionary (aruco, OpenCV 4.6 contrib), in
// the same run, one thread each:
//  - the reference library's own test photo (799 x 533, 12 tags of about 28 px; expected corners
//    from the library's test suite): time per frame, recall, worst corner error;
//  - a simulated 640 x 480 frame: six tags of 60-90 px (the size of a crate's tag at 0.5-0.8 m),
//    rotated and tilted, rendered with their true corners: the same three figures.
// Counters: found (of expected), extra (detections matching nothing), max_corner_px (each expected
// tag against its detection, over the four corners in the best cyclic order).
// Run: build/tests/mbot_vision_benchmark [--benchmark_repetitions=5 --benchmark_report_aggregates_only=true]
// Data: $MBOT_DATASETS_DIR, else the configured MBOT_DATASETS_DIR; missing data skips with an error.
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/aruco.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "mbot/common/config.hpp"
#include "mbot/vision/apriltag_detector.hpp"

namespace {

using Quad = std::array<cv::Point2d, 4>;

struct Scene {
  cv::Mat gray;
  std::vector<Quad> truth;
  std::string error;  // why the scene could not be made
};

Scene Photo() {
  Scene s;
  const std::string dir = mbot::config::DatasetsDir() + "/camera/apriltag/";
  s.gray = cv::imread(dir + "33369213973_9d9bb4cc96_c.jpg", cv::IMREAD_GRAYSCALE);
  std::ifstream in(dir + "33369213973_9d9bb4cc96_c.txt");
  if (s.gray.empty() || !in) s.error = "no " + dir + "33369213973_9d9bb4cc96_c.{jpg,txt}";
  for (std::string line; std::getline(in, line);) {
    for (char& c : line) {
      if (c == ',' || c == '(' || c == ')') c = ' ';
    }
    std::istringstream f(line);
    int id;
    Quad q;
    if (!(f >> id)) continue;
    for (auto& p : q) f >> p.x >> p.y;
    s.truth.push_back(q);
  }
  return s;
}

// Six tag36h11 tags (ids 0-5) warped onto a grey 640 x 480 frame; the truth is the warped corners of
// each black square (its outer edges, pixel centres at integers as OpenCV has them).
Scene Simulated() {
  Scene s;
  s.gray = cv::Mat(480, 640, CV_8UC1, cv::Scalar(150));
  const double sides[] = {60, 70, 80, 90, 65, 85};
  const double angles[] = {0.0, 0.3, -0.5, 1.2, 2.4, -2.0};
  for (int i = 0; i < 6; ++i) {
    const cv::Mat tag = mbot::vision::TagImage("tag36h11", i, 10);  // 100 px, black square 10..90
    const double side = sides[i], a = angles[i];
    const cv::Point2d centre(110 + (i % 3) * 210, 130 + (i / 3) * 230);
    // A similarity plus a small perspective tilt.
    // The black square's outer edges, pixel centres at integers (OpenCV's convention): 9.5 and 89.5.
    std::vector<cv::Point2f> src = {{9.5f, 9.5f}, {89.5f, 9.5f}, {89.5f, 89.5f}, {9.5f, 89.5f}}, dst;
    for (int k = 0; k < 4; ++k) {
      const double u = (src[k].x - 49.5) / 80 * side, v = (src[k].y - 49.5) / 80 * side;
      const double tilt = 1.0 + 0.15 * (k == 1 || k == 2 ? 1 : -1) * (i % 2 ? 1 : -1);
      dst.emplace_back(static_cast<float>(centre.x + tilt * (u * std::cos(a) - v * std::sin(a))),
                       static_cast<float>(centre.y + tilt * (u * std::sin(a) + v * std::cos(a))));
    }
    const cv::Mat H = cv::getPerspectiveTransform(src, dst);
    cv::Mat warped, mask;
    cv::warpPerspective(tag, warped, H, s.gray.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
    cv::warpPerspective(cv::Mat(tag.size(), CV_8UC1, cv::Scalar(255)), mask, H, s.gray.size(), cv::INTER_NEAREST);
    warped.copyTo(s.gray, mask);
    Quad q;
    for (int k = 0; k < 4; ++k) q[k] = dst[k];
    s.truth.push_back(q);
  }
  return s;
}

cv::Point2d Centre(const Quad& q) { return (q[0] + q[1] + q[2] + q[3]) / 4.0; }

// Matches detections to the truth by centre (within half the tag's size); reports the counters.
void Score(benchmark::State& state, const Scene& s, const std::vector<Quad>& found) {
  int matched = 0;
  double worst = 0.0;
  std::vector<bool> used(found.size(), false);
  for (const Quad& t : s.truth) {
    const double size = cv::norm(t[0] - t[2]) / 2;
    int best = -1;
    for (size_t i = 0; i < found.size(); ++i) {
      if (!used[i] && cv::norm(Centre(found[i]) - Centre(t)) < size &&
          (best < 0 || cv::norm(Centre(found[i]) - Centre(t)) < cv::norm(Centre(found[best]) - Centre(t))))
        best = static_cast<int>(i);
    }
    if (best < 0) continue;
    used[best] = true;
    ++matched;
    double err = 1e9;  // the best cyclic order, either winding
    for (int shift = 0; shift < 4; ++shift) {
      for (int dir : {1, -1}) {
        double e = 0;
        for (int k = 0; k < 4; ++k) e = std::max(e, cv::norm(found[best][(shift + dir * k + 8) % 4] - t[k]));
        err = std::min(err, e);
      }
    }
    worst = std::max(worst, err);
  }
  state.counters["expected"] = static_cast<double>(s.truth.size());
  state.counters["found"] = matched;
  state.counters["extra"] = static_cast<double>(found.size() - matched);
  state.counters["max_corner_px"] = worst;
}

void Reference(benchmark::State& state, const Scene& s, double decimate) {
  if (!s.error.empty()) return state.SkipWithError(s.error.c_str());
  mbot::vision::TagDetectorOptions o;
  o.decimate = decimate;
  const mbot::vision::TagDetector detector(o);
  std::vector<mbot::vision::TagDetection> found;
  for (auto _ : state) {
    found = detector.Detect(s.gray);
    benchmark::DoNotOptimize(found.data());
  }
  std::vector<Quad> quads;
  for (const auto& d : found) quads.push_back(d.corners);
  Score(state, s, quads);
}

void Aruco(benchmark::State& state, const Scene& s, int refinement) {
  if (!s.error.empty()) return state.SkipWithError(s.error.c_str());
  cv::setNumThreads(1);
  const cv::Ptr<cv::aruco::Dictionary> dict = cv::aruco::getPredefinedDictionary(cv::aruco::DICT_APRILTAG_36h11);
  const cv::Ptr<cv::aruco::DetectorParameters> params = cv::aruco::DetectorParameters::create();
  params->cornerRefinementMethod = refinement;
  std::vector<std::vector<cv::Point2f>> corners;
  std::vector<int> ids;
  for (auto _ : state) {
    cv::aruco::detectMarkers(s.gray, dict, corners, ids, params);
    benchmark::DoNotOptimize(ids.data());
  }
  std::vector<Quad> quads;
  for (const auto& c : corners) quads.push_back({c[0], c[1], c[2], c[3]});
  Score(state, s, quads);
}

const Scene& PhotoScene() {
  static const Scene s = Photo();
  return s;
}
const Scene& SimulatedScene() {
  static const Scene s = Simulated();
  return s;
}

void BM_Photo_Reference_Decimate1(benchmark::State& st) { Reference(st, PhotoScene(), 1.0); }
void BM_Photo_Reference_Decimate2(benchmark::State& st) { Reference(st, PhotoScene(), 2.0); }
void BM_Photo_Aruco_NoRefine(benchmark::State& st) { Aruco(st, PhotoScene(), cv::aruco::CORNER_REFINE_NONE); }
void BM_Photo_Aruco_Subpix(benchmark::State& st) { Aruco(st, PhotoScene(), cv::aruco::CORNER_REFINE_SUBPIX); }
void BM_Photo_Aruco_AprilTagRefine(benchmark::State& st) { Aruco(st, PhotoScene(), cv::aruco::CORNER_REFINE_APRILTAG); }
void BM_Sim640_Reference_Decimate1(benchmark::State& st) { Reference(st, SimulatedScene(), 1.0); }
void BM_Sim640_Reference_Decimate2(benchmark::State& st) { Reference(st, SimulatedScene(), 2.0); }
void BM_Sim640_Aruco_NoRefine(benchmark::State& st) { Aruco(st, SimulatedScene(), cv::aruco::CORNER_REFINE_NONE); }
void BM_Sim640_Aruco_Subpix(benchmark::State& st) { Aruco(st, SimulatedScene(), cv::aruco::CORNER_REFINE_SUBPIX); }
void BM_Sim640_Aruco_AprilTagRefine(benchmark::State& st) {
  Aruco(st, SimulatedScene(), cv::aruco::CORNER_REFINE_APRILTAG);
}

BENCHMARK(BM_Photo_Reference_Decimate1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Photo_Reference_Decimate2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Photo_Aruco_NoRefine)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Photo_Aruco_Subpix)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Photo_Aruco_AprilTagRefine)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Sim640_Reference_Decimate1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Sim640_Reference_Decimate2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Sim640_Aruco_NoRefine)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Sim640_Aruco_Subpix)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Sim640_Aruco_AprilTagRefine)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
