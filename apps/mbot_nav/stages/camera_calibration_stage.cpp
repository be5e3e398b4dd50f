// `camera_calibration`: chessboard calibration of the camera (libs/vision) from a folder of images,
// one image or a video. Writes camera.yaml (OpenCV's FileStorage, OpenCV's key names) and camera.ini
// (an INI snippet) only when accepted; always calibration.json (every view, found or rejected, its
// error), calibration_corners.png (the corners found in the first view with a board) and
// calibration_undistorted.png (that view undistorted). Not accepted (too few views, or a mean
// reprojection error above max_error_px) fails the run, saying why.
#include <filesystem>
#include <opencv2/calib3d.hpp>
#include <sstream>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/vision/camera_calibration.hpp"
#include "mbot/vision/frame.hpp"
#include "mbot/vision/images.hpp"
#include "mbot/reports/json.hpp"
#include "report.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

struct CameraCalibrationOptions {
  vision::ChessboardOptions board;
  int every = 1;  // use every n-th frame of the source
};

reports::Json Json(const vision::CalibrationResult& r, const CameraCalibrationOptions& o, const std::string& images) {
  using reports::Number;
  reports::Json j = {{"images", images},
                     {"board",
                      {{"inner_cols", o.board.inner_cols},
                       {"inner_rows", o.board.inner_rows},
                       {"square_m", Number(o.board.square_m)}}},
                     {"image_width", r.image_width},
                     {"image_height", r.image_height},
                     {"flags", r.flags},
                     {"views", r.views.size()},
                     {"used", r.UsedViews()},
                     {"calibrated", r.calibrated},
                     {"accepted", r.accepted},
                     {"verdict", r.verdict}};
  if (r.calibrated) {
    const cv::Mat& k = r.camera_matrix;
    j["fx"] = Number(k.at<double>(0, 0));
    j["fy"] = Number(k.at<double>(1, 1));
    j["cx"] = Number(k.at<double>(0, 2));
    j["cy"] = Number(k.at<double>(1, 2));
    j["distortion"] = reports::Json::array();
    for (int i = 0; i < r.distortion.rows; ++i) j["distortion"].push_back(Number(r.distortion.at<double>(i, 0)));
    j["avg_reprojection_error_px"] = Number(r.avg_error_px);
  }
  j["per_view"] = reports::Json::array();
  for (const vision::CalibrationView& v : r.views) {
    reports::Json view = {{"view", v.name}, {"board", v.found}};
    if (v.found && r.calibrated) view["error_px"] = Number(v.error_px);
    j["per_view"].push_back(std::move(view));
  }
  return j;
}

class CameraCalibrationStage : public Stage {
 public:
  explicit CameraCalibrationStage(CameraCalibrationOptions o) : o_(std::move(o)) {}
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
    const vision::CalibrationResult r = vision::CalibrateChessboard(views, o_.board);
    const std::string dir = ctx.output_dir;
    reports::WriteJson(dir + "/calibration.json", Json(r, o_, images_));
    for (size_t i = 0; i < r.views.size(); ++i) {
      if (!r.views[i].found) continue;
      cv::Mat shown = vision::ToBgr(views[i].second);  // grey, BGR or BGRA views alike
      cv::drawChessboardCorners(shown, cv::Size(o_.board.inner_cols, o_.board.inner_rows), r.views[i].corners, true);
      vision::WriteImage(shown, dir + "/calibration_corners.png");
      if (r.calibrated) {
        cv::Mat undistorted;
        cv::undistort(views[i].second, undistorted, r.camera_matrix, r.distortion);
        vision::WriteImage(undistorted, dir + "/calibration_undistorted.png");
      }
      break;
    }
    std::string rejected;
    for (const auto& v : r.views) {
      if (!v.found) rejected += (rejected.empty() ? "" : ", ") + v.name;
    }
    if (!rejected.empty()) mbot::log::Warn("camera_calibration: no whole board in " + rejected + " (rejected)");
    if (!r.accepted) {
      throw std::runtime_error("camera_calibration: " + r.verdict + " (report in " + dir + "/calibration.json)");
    }
    vision::WriteCameraYaml(r, o_.board, dir + "/camera.yaml");
    const cv::Mat& k = r.camera_matrix;
    WriteFileAtomically(dir + "/camera.ini", [&](std::ostream& out) {
      out << "# Camera intrinsics from " << images_ << " (" << r.verdict << ")\n[camera]\n"
          << "image_width = " << r.image_width << "\nimage_height = " << r.image_height
          << "\nfx = " << Num(k.at<double>(0, 0), 10) << "\nfy = " << Num(k.at<double>(1, 1), 10)
          << "\ncx = " << Num(k.at<double>(0, 2), 10) << "\ncy = " << Num(k.at<double>(1, 2), 10) << "\ndistortion = ";
      for (int i = 0; i < r.distortion.rows; ++i) out << (i ? ", " : "") << Num(r.distortion.at<double>(i, 0), 10);
      out << "\n";
    });
    std::printf(
        "camera_calibration: %s\n  fx %.2f  fy %.2f  cx %.2f  cy %.2f px; wrote camera.yaml, camera.ini in %s\n",
        r.verdict.c_str(), k.at<double>(0, 0), k.at<double>(1, 1), k.at<double>(0, 2), k.at<double>(1, 2), dir.c_str());
  }

 private:
  CameraCalibrationOptions o_;
  std::string images_;  // the source's path
  long long frames_ = 0;
  std::vector<std::pair<std::string, cv::Mat>> views_;
};

}  // namespace

static StageType CameraCalibrationStageType() {
  return {"camera_calibration",
          "chessboard camera calibration (sub-pixel corners, cv::calibrateCamera) from a folder of images, an image or "
          "a video; writes camera.yaml with OpenCV's keys, camera.ini, calibration.json and PNGs",
          [](config::Section& s) -> std::unique_ptr<Stage> {
            CameraCalibrationOptions o;
            vision::ChessboardOptions& b = o.board;
            o.every = s.GetInt("every_nth_frame", o.every, "use every n-th frame of the source (a video)", 1, 100000);
            b.inner_cols = s.GetInt("inner_cols", b.inner_cols, "inner corners along a row of the board", 2, 100);
            b.inner_rows = s.GetInt("inner_rows", b.inner_rows, "inner corners along a column of the board", 2, 100);
            b.square_m = s.GetDouble("square_m", b.square_m, "side of a square [m]", 1e-4, 10.0);
            b.subpixel_half_window = s.GetInt("subpixel_half_window", b.subpixel_half_window,
                                              "cv::cornerSubPix winSize (the window is 2n + 1 px)", 1, 100);
            b.fix_aspect_ratio =
                s.GetBool("fix_aspect_ratio", b.fix_aspect_ratio, "CALIB_FIX_ASPECT_RATIO: fx / fy stays aspect_ratio");
            b.aspect_ratio = s.GetDouble("aspect_ratio", b.aspect_ratio, "fx / fy with fix_aspect_ratio", 0.01, 100.0);
            b.zero_tangent_dist = s.GetBool("zero_tangent_dist", b.zero_tangent_dist, "CALIB_ZERO_TANGENT_DIST");
            b.fix_principal_point =
                s.GetBool("fix_principal_point", b.fix_principal_point, "CALIB_FIX_PRINCIPAL_POINT");
            b.fix_k3 = s.GetBool("fix_k3", b.fix_k3, "CALIB_FIX_K3");
            b.rational_model = s.GetBool("rational_model", b.rational_model, "CALIB_RATIONAL_MODEL (k4-k6)");
            b.min_views = s.GetInt("min_views", b.min_views, "fewer views with a whole board fail the run", 1, 10000);
            b.max_error_px = s.GetDouble("max_error_px", b.max_error_px,
                                         "a mean reprojection error above this fails the run [px]", 0.0, 100.0);
            return std::make_unique<CameraCalibrationStage>(o);
          }};
}

const RegisterStage kCameraCalibrationRegistered{CameraCalibrationStageType()};

}  // namespace mbot::app
