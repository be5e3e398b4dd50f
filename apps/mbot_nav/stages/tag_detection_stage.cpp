// `tag_detection`: AprilTag detection (libs/vision, the reference detector) on a folder of images,
// one image or a video. Writes tags.csv (image,id,x0,y0,x1,y1,x2,y2,x3,y3,margin: corners in the
// library's order and pixel convention), an annotated PNG per image (<name>_tags.png; not for video
// frames unless asked) and tags.json (counts, time per frame).
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <sstream>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/vision/apriltag_detector.hpp"
#include "mbot/vision/frame.hpp"
#include "mbot/vision/images.hpp"
#include "mbot/vision/vision_config.hpp"
#include "mbot/reports/json.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

struct TagDetectionOptions {
  vision::TagDetectorOptions detector;
  int every = 1;  // use every n-th frame of the source
  bool annotate = true;
  int timing_repeats = 1;  // detect each frame this many times; the time is their median
};

class TagDetectionStage : public Stage {
 public:
  explicit TagDetectionStage(TagDetectionOptions o) : o_(std::move(o)), detector_(o_.detector) {}
  void Start(const RunContext& ctx) override { images_ = ctx.source_path; }
  void OnEvent(const msgs::Event& ev) override {
    if (ev.kind != msgs::EventKind::kCameraFrame) return;
    const auto& frame = std::get<msgs::CameraFrame>(ev.payload);
    if (frames_++ % o_.every == 0) views_.emplace_back(frame.name, vision::FrameImage(frame).clone());
  }

  void Finish(const RunContext& ctx, bool interrupted) override {
    if (interrupted) return;
    const auto& views = views_;
    if (views.empty()) throw std::runtime_error(images_ + ": no camera frames (is [source] type = camera?)");
    const bool video = !views.empty() && views[0].first.rfind("frame ", 0) == 0;
    std::ostringstream csv;
    csv << "image,id,x0,y0,x1,y1,x2,y2,x3,y3,margin\n";
    std::vector<double> ms;
    size_t total = 0;
    std::map<int, int> per_id;
    for (const auto& [name, image] : views) {
      auto t0 = std::chrono::steady_clock::now();
      const std::vector<vision::TagDetection> tags = detector_.Detect(image);
      std::vector<double> runs = {
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count()};
      for (int k = 1; k < o_.timing_repeats; ++k) {  // the same frame again, for the time only
        t0 = std::chrono::steady_clock::now();
        const size_t again = detector_.Detect(image).size();
        runs.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
        if (again != tags.size()) mbot::log::Warn("tag_detection: " + name + " gave a different count when repeated");
      }
      std::nth_element(runs.begin(), runs.begin() + runs.size() / 2, runs.end());
      ms.push_back(runs[runs.size() / 2]);
      total += tags.size();
      for (const vision::TagDetection& t : tags) {
        ++per_id[t.id];
        char row[320];
        std::snprintf(row, sizeof row, "%s,%d,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.3f\n", name.c_str(), t.id,
                      t.corners[0].x, t.corners[0].y, t.corners[1].x, t.corners[1].y, t.corners[2].x, t.corners[2].y,
                      t.corners[3].x, t.corners[3].y, t.margin);
        csv << row;
      }
      if (o_.annotate && !video) {
        const std::string stem = std::filesystem::path(name).stem().string();
        vision::WriteImage(vision::DrawTags(image, tags), ctx.output_dir + "/" + stem + "_tags.png");
      }
    }
    WriteFileAtomically(ctx.output_dir + "/tags.csv", [&](std::ostream& out) { out << csv.str(); });
    std::vector<double> sorted = ms;
    std::sort(sorted.begin(), sorted.end());
    const double median = sorted[sorted.size() / 2];
    reports::Json ids = reports::Json::object();
    for (const auto& [id, n] : per_id) ids[std::to_string(id)] = n;
    reports::WriteJson(
        ctx.output_dir + "/tags.json",
        {{"images", images_},
         {"family", o_.detector.family},
         {"decimate", reports::Number(o_.detector.decimate)},
         {"refine_edges", o_.detector.refine_edges},
         {"threads", o_.detector.threads},
         {"frames", views.size()},
         {"detections", total},
         {"per_id", std::move(ids)},
         {"ms_per_frame", {{"median", reports::Number(median)}, {"max", reports::Number(sorted.back())}}}});
    std::printf("tag_detection: %zu tags in %zu frames (%s), median %.2f ms per frame; tags.csv, tags.json in %s\n",
                total, views.size(), o_.detector.family.c_str(), median, ctx.output_dir.c_str());
  }

 private:
  TagDetectionOptions o_;
  vision::TagDetector detector_;
  std::string images_;  // the source's path
  long long frames_ = 0;
  std::vector<std::pair<std::string, cv::Mat>> views_;
};

}  // namespace

static StageType TagDetectionStageType() {
  return {"tag_detection",
          "AprilTag detection with the reference detector on a folder of images, an image or a video; writes "
          "tags.csv, tags.json and annotated PNGs",
          [](config::Section& s) -> std::unique_ptr<Stage> {
            TagDetectionOptions o;
            o.every = s.GetInt("every_nth_frame", o.every, "use every n-th frame of the source (a video)", 1, 100000);
            o.timing_repeats = s.GetInt("timing_repeats", o.timing_repeats,
                                        "detect each frame this many times and report the median time", 1, 10000);
            o.annotate =
                s.GetBool("annotate", o.annotate, "write <image>_tags.png with the tags drawn (not for video)");
            o.detector = vision::ParseTagDetectorOptions(s, o.detector);
            return std::make_unique<TagDetectionStage>(o);
          }};
}

const RegisterStage kTagDetectionRegistered{TagDetectionStageType()};

}  // namespace mbot::app
