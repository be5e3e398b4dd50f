// `tag_sightings`: the live camera's AprilTags. Each camera frame (a `camera` source: a device, a
// video, a GStreamer pipeline or an image folder) goes through the tag observer (libs/vision:
// detection, the pose of each tag in the camera frame, and through the mounting pose in the robot
// frame) and comes out as a kTagSightings event on `channel` (MBOT_APRILTAG_ARRAY), which an
// lcm_bridge or recorder stage after it publishes as the botlab's mbot_apriltag_array_t. Writes
// sightings.csv (every tag of every frame) and sightings.json (counts, time per frame) at the end.
// With a forklift on the stream (MBOT_FORKLIFT_STATUS), the frame before each lift and each set-down
// is kept with its detections drawn: forklift_<n>_<lift|set_down>_crate<id>.png.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <sstream>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/vision/apriltag_detector.hpp"
#include "mbot/vision/images.hpp"
#include "mbot/vision/tag_observer.hpp"
#include "mbot/vision/vision_config.hpp"
#include "mbot/reports/json.hpp"
#include "mbot/msgs/topics.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

struct TagSightingsOptions {
  vision::TagObserverOptions observer;
  std::string camera_yaml;
  std::string channel = msgs::topics::kTags;
};

class TagSightingsStage : public Stage {
 public:
  explicit TagSightingsStage(TagSightingsOptions o) : o_(std::move(o)) {}

  void Start(const RunContext& ctx) override {
    observer_.emplace(o_.observer, vision::IntrinsicsFromYaml(o_.camera_yaml));  // files open at start
    bus_ = ctx.bus;
    output_dir_ = ctx.output_dir;
    csv_ << "t_s,frame,id,x_m,y_m,z_m,robot_x_m,robot_y_m,bearing_deg,reprojection_px,margin\n";
  }

  void OnEvent(const msgs::Event& ev) override {
    if (ev.kind == msgs::EventKind::kForkliftStatus) return ForkliftChanged(std::get<msgs::ForkliftStatus>(ev.payload));
    if (ev.kind != msgs::EventKind::kCameraFrame) return;
    const auto& frame = std::get<msgs::CameraFrame>(ev.payload);
    if (!frame.pixels || frame.pixels->size() != static_cast<size_t>(frame.width) * frame.height) return;
    const cv::Mat image(frame.height, frame.width, CV_8UC1, const_cast<uint8_t*>(frame.pixels->data()));
    const auto t0 = std::chrono::steady_clock::now();
    const std::vector<vision::ObservedTag> tags = observer_->Observe(image);
    ms_.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    last_frame_ = frame.pixels;
    last_size_ = {frame.width, frame.height};
    last_tags_.clear();
    for (const vision::ObservedTag& t : tags) last_tags_.push_back(t.detection);
    msgs::TagSightings out;
    for (const vision::ObservedTag& t : tags) {
      const auto& q = t.quaternion;
      msgs::TagSighting seen;
      seen.id = t.detection.id;
      seen.x_m = t.camera.t[0], seen.y_m = t.camera.t[1], seen.z_m = t.camera.t[2];
      seen.qw = q[0], seen.qx = q[1], seen.qy = q[2], seen.qz = q[3];
      seen.family = o_.observer.detector.family;
      seen.hamming = t.detection.hamming;
      seen.margin = t.detection.margin;
      seen.centre_px = {t.detection.center.x, t.detection.center.y};
      for (int k = 0; k < 4; ++k) {
        seen.corners_px[2 * k] = t.detection.corners[k].x;
        seen.corners_px[2 * k + 1] = t.detection.corners[k].y;
      }
      seen.homography = t.detection.homography;
      out.tags.push_back(std::move(seen));
      ++per_id_[t.detection.id];
      char row[320];
      std::snprintf(row, sizeof row, "%.6f,%s,%d,%.4f,%.4f,%.4f,%.4f,%.4f,%.2f,%.3f,%.2f\n", ev.t_us * 1e-6,
                    frame.name.c_str(), t.detection.id, t.camera.t[0], t.camera.t[1], t.camera.t[2],
                    t.robot_position[0], t.robot_position[1], t.robot_bearing_rad * 180.0 / M_PI,
                    t.camera.reprojection_error_px, t.detection.margin);
      csv_ << row;
    }
    ++frames_;
    msgs::Event sightings;
    sightings.kind = msgs::EventKind::kTagSightings;
    sightings.channel = o_.channel;
    sightings.t_us = ev.t_us;
    sightings.stamp_us = ev.stamp_us;
    sightings.payload = std::move(out);
    if (bus_) bus_->Emit(this, sightings);
  }

  void Finish(const RunContext& ctx, bool interrupted) override {
    WriteFileAtomically(ctx.output_dir + "/sightings.csv", [&](std::ostream& out) { out << csv_.str(); });
    std::vector<double> sorted = ms_;
    std::sort(sorted.begin(), sorted.end());
    const double median = sorted.empty() ? 0.0 : sorted[sorted.size() / 2];
    int64_t total = 0;
    reports::Json per_id = reports::Json::object();
    for (const auto& [id, n] : per_id_) {
      per_id[std::to_string(id)] = n;
      total += n;
    }
    reports::WriteJson(
        ctx.output_dir + "/sightings.json",
        {{"camera", o_.camera_yaml},
         {"channel", o_.channel},
         {"tag_size_m", reports::Number(o_.observer.tag_size_m)},
         {"frames", frames_},
         {"per_id", std::move(per_id)},
         {"sightings", total},
         {"ignored_ids", observer_->ignored()},
         {"ms_per_frame",
          {{"median", reports::Number(median)}, {"max", reports::Number(sorted.empty() ? 0 : sorted.back())}}},
         {"interrupted", interrupted}});
    mbot::log::Info("tag_sightings: " + std::to_string(total) + " tags in " + std::to_string(frames_) + " frames on " +
                    o_.channel + " (" + std::to_string(observer_->ignored()) + " of other ids ignored)");
  }

 private:
  // A lift (carrying begins) or a set-down (it ends): the last frame, with its tags drawn.
  void ForkliftChanged(const msgs::ForkliftStatus& f) {
    const bool changed = f.carrying != carrying_;
    carrying_ = f.carrying;
    if (f.crate_id >= 0) crate_ = f.crate_id;
    if (!changed || !last_frame_ || output_dir_.empty()) return;
    const cv::Mat image(last_size_.height, last_size_.width, CV_8UC1, const_cast<uint8_t*>(last_frame_->data()));
    const std::string name = output_dir_ + "/forklift_" + std::to_string(++snapshots_) + "_" +
                             (f.carrying ? "lift" : "set_down") + "_crate" + std::to_string(crate_) + ".png";
    try {
      vision::WriteImage(vision::DrawTags(image, last_tags_), name);
    } catch (const std::exception& e) {
      mbot::log::Warn("tag_sightings: " + std::string(e.what()));
    }
  }

  TagSightingsOptions o_;
  std::optional<vision::TagObserver> observer_;  // from Start
  Bus* bus_ = nullptr;
  std::ostringstream csv_;
  std::vector<double> ms_;
  std::map<int, int64_t> per_id_;
  int64_t frames_ = 0;
  std::string output_dir_;
  std::shared_ptr<const std::vector<uint8_t>> last_frame_;
  cv::Size last_size_;
  std::vector<vision::TagDetection> last_tags_;
  bool carrying_ = false;
  int crate_ = -1, snapshots_ = 0;
};

}  // namespace

static StageType TagSightingsStageType() {
  return {"tag_sightings",
          "camera frames → AprilTag poses in the camera and robot frames, emitted on MBOT_APRILTAG_ARRAY "
          "(kTagSightings); sightings.csv, sightings.json",
          [](config::Section& s) -> std::unique_ptr<Stage> {
            TagSightingsOptions o;
            o.camera_yaml = s.RequirePath("camera", "the camera's calibration (camera.yaml, OpenCV's key names)");
            o.channel = s.GetString("channel", o.channel, "the channel the sightings are emitted on");
            o.observer = vision::ParseTagObserverOptions(s, o.observer);
            return std::make_unique<TagSightingsStage>(o);
          }};
}

const RegisterStage kTagSightingsRegistered{TagSightingsStageType()};

}  // namespace mbot::app
