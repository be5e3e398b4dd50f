// Chessboard camera calibration, the botlab's way and OpenCV's: inner corners found in each view
// and refined to sub-pixel, cv::calibrateCamera on the accepted views, the result judged by its mean
// reprojection error (the botlab accepts below 0.5 px) and written as OpenCV's camera.yaml.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace mbot::vision {

struct ChessboardOptions {
  int inner_cols = 9;  // inner corners along a row of the board
  int inner_rows = 6;  // inner corners along a column
  double square_m = 0.025;
  int subpixel_half_window = 11;  // cv::cornerSubPix winSize (the window is 2n + 1 px; OpenCV sample: 11)
  // Calibration flags, OpenCV's names.
  bool fix_aspect_ratio = false;  // CALIB_FIX_ASPECT_RATIO with fx / fy = aspect_ratio
  double aspect_ratio = 1.0;
  bool zero_tangent_dist = false;    // CALIB_ZERO_TANGENT_DIST
  bool fix_principal_point = false;  // CALIB_FIX_PRINCIPAL_POINT
  bool fix_k3 = false;               // CALIB_FIX_K3
  bool rational_model = false;       // CALIB_RATIONAL_MODEL (k4-k6)
  int min_views = 5;                 // fewer accepted views: not calibrated
  double max_error_px = 0.5;         // mean reprojection error above this: not accepted
};

struct CalibrationView {
  std::string name;                  // file name, or "frame N" of a video
  bool found = false;                // a whole board was found
  std::vector<cv::Point2f> corners;  // sub-pixel, OpenCV's order
  double error_px = 0.0;             // RMS reprojection error of this view (found views)
};

struct CalibrationResult {
  int image_width = 0, image_height = 0;
  std::vector<CalibrationView> views;  // every view, in input order
  cv::Mat camera_matrix;               // 3 × 3, CV_64F
  cv::Mat distortion;                  // k1 k2 p1 p2 k3 [k4 k5 k6], CV_64F, one column
  double avg_error_px = 0.0;           // OpenCV's avg_reprojection_error (RMS over all points)
  int flags = 0;                       // the cv::calibrateCamera flags used
  bool calibrated = false;             // calibrateCamera ran (enough views)
  bool accepted = false;               // calibrated and avg_error_px <= max_error_px
  std::string verdict;                 // why not, or "accepted: …"
  int UsedViews() const;
};

// Calibrates from images (grayscale or colour, one size). Views without a whole board are kept in
// `views` as not found. Throws std::invalid_argument for bad options or images of different sizes
// (naming the view).
CalibrationResult CalibrateChessboard(const std::vector<std::pair<std::string, cv::Mat>>& images,
                                      const ChessboardOptions& options);

// camera.yaml in OpenCV's FileStorage format with OpenCV's key names (image_width, image_height,
// camera_matrix, distortion_coefficients, avg_reprojection_error, per_view_reprojection_errors, and
// the board and flags), written whole or not at all.
void WriteCameraYaml(const CalibrationResult& r, const ChessboardOptions& o, const std::string& path);
// Reads camera_matrix, distortion_coefficients, image_width and image_height back; throws naming the
// file and key when one is missing or cannot be right: a line OpenCV's writer does not make, an image
// size outside 1-16384 px, a camera matrix with a non-finite element, a last row other than 0 0 1 or
// a focal length not in (0, 100 × the longer side], distortion that is not 0, 4, 5, 8, 12 or 14
// finite values (returned as one row of doubles).
CalibrationResult ReadCameraYaml(const std::string& path);

}  // namespace mbot::vision
