#include "mbot/vision/camera_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <stdexcept>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/files.hpp"
#include "mbot/common/strings.hpp"

namespace mbot::vision {
namespace {

int Flags(const ChessboardOptions& o) {
  int f = 0;
  if (o.fix_aspect_ratio) f |= cv::CALIB_FIX_ASPECT_RATIO;
  if (o.zero_tangent_dist) f |= cv::CALIB_ZERO_TANGENT_DIST;
  if (o.fix_principal_point) f |= cv::CALIB_FIX_PRINCIPAL_POINT;
  if (o.fix_k3) f |= cv::CALIB_FIX_K3;
  if (o.rational_model) f |= cv::CALIB_RATIONAL_MODEL;
  return f;
}

}  // namespace

int CalibrationResult::UsedViews() const {
  return static_cast<int>(std::count_if(views.begin(), views.end(), [](const CalibrationView& v) { return v.found; }));
}

CalibrationResult CalibrateChessboard(const std::vector<std::pair<std::string, cv::Mat>>& images,
                                      const ChessboardOptions& o) {
  if (o.inner_cols < 2 || o.inner_rows < 2) throw std::invalid_argument("chessboard: at least 2 x 2 inner corners");
  if (!(o.square_m > 0)) throw std::invalid_argument("chessboard: square size must be positive");
  if (o.fix_aspect_ratio && !(o.aspect_ratio > 0)) throw std::invalid_argument("chessboard: aspect_ratio must be > 0");
  CalibrationResult r;
  r.flags = Flags(o);
  const cv::Size pattern(o.inner_cols, o.inner_rows);
  std::vector<cv::Point3f> board;  // the corners on the board plane, OpenCV's order (row by row)
  for (int i = 0; i < o.inner_rows; ++i) {
    for (int j = 0; j < o.inner_cols; ++j)
      board.emplace_back(static_cast<float>(j * o.square_m), static_cast<float>(i * o.square_m), 0.0f);
  }
  std::vector<std::vector<cv::Point3f>> object_points;
  std::vector<std::vector<cv::Point2f>> image_points;
  std::vector<size_t> used;  // index into r.views of each calibrated view
  for (const auto& [name, image] : images) {
    if (image.empty()) throw std::invalid_argument(name + ": empty image");
    if (r.image_width == 0) r.image_width = image.cols, r.image_height = image.rows;
    if (image.cols != r.image_width || image.rows != r.image_height) {
      throw std::invalid_argument(name + ": " + std::to_string(image.cols) + " x " + std::to_string(image.rows) +
                                  " differs from the first view's " + std::to_string(r.image_width) + " x " +
                                  std::to_string(r.image_height));
    }
    cv::Mat gray;
    if (image.channels() == 1) {
      gray = image;
    } else {
      cv::cvtColor(image, gray, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
    }
    CalibrationView v;
    v.name = name;
    // OpenCV's calibration sample: adaptive threshold, normalised image, fast check first.
    v.found = cv::findChessboardCorners(
        gray, pattern, v.corners,
        cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_FAST_CHECK | cv::CALIB_CB_NORMALIZE_IMAGE);
    if (v.found) {
      const int w = std::max(1, o.subpixel_half_window);
      cv::cornerSubPix(gray, v.corners, cv::Size(w, w), cv::Size(-1, -1),
                       cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 30, 0.0001));
      object_points.push_back(board);
      image_points.push_back(v.corners);
      used.push_back(r.views.size());
    } else {
      v.corners.clear();
    }
    r.views.push_back(std::move(v));
  }
  if (static_cast<int>(used.size()) < std::max(1, o.min_views)) {
    r.verdict = "not calibrated: the board was found in " + std::to_string(used.size()) + " of " +
                std::to_string(images.size()) + " views, fewer than min_views = " + std::to_string(o.min_views);
    return r;
  }
  r.camera_matrix = cv::Mat::eye(3, 3, CV_64F);
  if (o.fix_aspect_ratio) r.camera_matrix.at<double>(0, 0) = o.aspect_ratio;
  r.distortion = cv::Mat::zeros(o.rational_model ? 8 : 5, 1, CV_64F);
  std::vector<cv::Mat> rvecs, tvecs;
  cv::calibrateCamera(object_points, image_points, cv::Size(r.image_width, r.image_height), r.camera_matrix,
                      r.distortion, rvecs, tvecs, r.flags | cv::CALIB_FIX_K4 | cv::CALIB_FIX_K5);
  r.calibrated = true;
  // Reprojection errors as OpenCV's sample reports them: per view sqrt(mean squared distance), and
  // overall sqrt(sum of squared distances / all points).
  double total2 = 0.0;
  size_t total_points = 0;
  for (size_t k = 0; k < used.size(); ++k) {
    std::vector<cv::Point2f> projected;
    cv::projectPoints(object_points[k], rvecs[k], tvecs[k], r.camera_matrix, r.distortion, projected);
    const double e = cv::norm(image_points[k], projected, cv::NORM_L2);
    total2 += e * e;
    total_points += projected.size();
    r.views[used[k]].error_px = std::sqrt(e * e / projected.size());
  }
  r.avg_error_px = std::sqrt(total2 / total_points);
  r.accepted = r.avg_error_px <= o.max_error_px;
  char b[160];
  std::snprintf(b, sizeof b, "%s: mean reprojection error %.3f px %s %.2f px over %d views",
                r.accepted ? "accepted" : "not accepted", r.avg_error_px, r.accepted ? "<=" : ">", o.max_error_px,
                static_cast<int>(used.size()));
  r.verdict = b;
  return r;
}

void WriteCameraYaml(const CalibrationResult& r, const ChessboardOptions& o, const std::string& path) {
  const std::string tmp = TempPathFor(path);
  {
    cv::FileStorage fs(tmp, cv::FileStorage::WRITE);
    if (!fs.isOpened()) throw std::runtime_error(path + ": cannot be written");
    fs << "nframes" << r.UsedViews();
    fs << "image_width" << r.image_width << "image_height" << r.image_height;
    fs << "board_width" << o.inner_cols << "board_height" << o.inner_rows << "square_size" << o.square_m;
    if (o.fix_aspect_ratio) fs << "aspectRatio" << o.aspect_ratio;
    fs << "flags" << r.flags;
    fs << "camera_matrix" << r.camera_matrix << "distortion_coefficients" << r.distortion;
    fs << "avg_reprojection_error" << r.avg_error_px;
    std::vector<float> per_view;
    for (const CalibrationView& v : r.views) {
      if (v.found) per_view.push_back(static_cast<float>(v.error_px));
    }
    fs << "per_view_reprojection_errors" << cv::Mat(per_view, true);
  }
  CommitFile(tmp, path);
}

namespace {

// OpenCV 4.6's YAML parser loops forever on some malformed text ("%YAML:1.0\n a:[]\na---\n", found by
// the camera_yaml fuzz target), so a camera file is checked line by line first: the lines OpenCV's
// writer makes (a %YAML header, ---, comments, `key: value`, `key: !!opencv-matrix`) and data lines
// of numbers only. Anything else is refused naming the line.
void CheckCameraText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  int line_no = 0;
  size_t total = 0;
  auto number = [](const std::string& t) {
    static const char* const kSpecial[] = {".nan", ".NaN", ".NAN", ".inf", ".Inf", ".INF", "-.inf", "-.Inf", "-.INF"};
    for (const char* s : kSpecial) {
      if (t == s) return true;
    }
    char* end = nullptr;
    std::strtod(t.c_str(), &end);
    return !t.empty() && end == t.c_str() + t.size();
  };
  while (std::getline(in, line)) {
    ++line_no;
    total += line.size() + 1;
    if (total > (1u << 20)) throw std::runtime_error(path + ": larger than 1 MiB: not a camera file");
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    const std::string t = line.substr(first);
    if ((line_no == 1 && t.rfind("%YAML", 0) == 0) || t == "---") continue;
    const size_t colon = t.find(':');
    const bool key = colon != std::string::npos && colon > 0 &&
                     t.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_") == colon;
    std::string rest = key ? t.substr(colon + 1) : t;
    if (key && rest.find("!!opencv-matrix") != std::string::npos) continue;
    // A quoted text value (OpenCV's calibration sample writes calibration_time: "Thu Dec  4 …").
    const std::string value = Trim(rest);
    if (key && value.size() >= 2 && value.front() == '"' && value.find('"', 1) == value.size() - 1) continue;
    // A value or a data line: numbers, with the brackets and commas of a sequence, or a word value
    // (dt: d, a calibration's date).
    bool ok = true;
    std::string token;
    int words = 0;
    for (size_t i = 0; i <= rest.size(); ++i) {
      const char c = i < rest.size() ? rest[i] : ' ';
      if (c == ' ' || c == '\t' || c == ',' || c == '[' || c == ']') {
        if (!token.empty() && !number(token)) {
          ok = key && token.find_first_of("-:[]{}") == std::string::npos;
          ++words;
        }
        if (!ok) break;
        token.clear();
      } else {
        token += c;
      }
    }
    if (!ok || (!key && words > 0) || (key && rest.find_first_of("{}\"'") != std::string::npos)) {
      throw std::runtime_error(path + ": line " + std::to_string(line_no) + ": '" + t.substr(0, 80) +
                               "' is not a line of an OpenCV camera file");
    }
  }
}

// The largest image side a camera file may give [px].
constexpr int kMaxCameraSidePx = 16384;

// Refuses a camera that cannot be right, naming `path` and the key (ReadCameraYaml says which);
// the distortion comes back as one row of doubles.
void ValidateCamera(CalibrationResult& r, const std::string& path) {
  auto fail = [&](const std::string& key, const std::string& why) {
    throw std::runtime_error(path + ": " + key + ": " + why);
  };
  auto text = [](double v) { return std::isnan(v) ? std::string("nan") : std::to_string(v); };
  if (r.image_width < 1 || r.image_width > kMaxCameraSidePx)
    fail("image_width", std::to_string(r.image_width) + " px is not in 1-" + std::to_string(kMaxCameraSidePx));
  if (r.image_height < 1 || r.image_height > kMaxCameraSidePx)
    fail("image_height", std::to_string(r.image_height) + " px is not in 1-" + std::to_string(kMaxCameraSidePx));
  const cv::Mat& k = r.camera_matrix;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (!std::isfinite(k.at<double>(i, j)))
        fail("camera_matrix",
             "element (" + std::to_string(i) + ", " + std::to_string(j) + ") is " + text(k.at<double>(i, j)));
    }
  }
  if (k.at<double>(1, 0) != 0.0 || k.at<double>(2, 0) != 0.0 || k.at<double>(2, 1) != 0.0 || k.at<double>(2, 2) != 1.0)
    fail("camera_matrix", "is not a camera matrix (its last row must be 0 0 1, and K(1,0) 0)");
  // A focal length is positive and, in pixels, not far beyond the image: 100 × the longer side is a
  // 0.5° field of view.
  const double max_f = 100.0 * std::max(r.image_width, r.image_height);
  for (const auto& [name, f] : {std::pair<const char*, double>{"fx", k.at<double>(0, 0)}, {"fy", k.at<double>(1, 1)}}) {
    if (!(f > 0.0 && f <= max_f)) {
      fail("camera_matrix", std::string(name) + " = " + text(f) + " is not a focal length (0 < " + name +
                                " <= " + std::to_string(static_cast<long long>(max_f)) + " px)");
    }
  }
  cv::Mat& d = r.distortion;
  if (!d.empty()) {
    if ((d.rows != 1 && d.cols != 1) || (d.type() != CV_64F && d.type() != CV_32F))
      fail("distortion_coefficients", "is not a row or column of numbers");
    d.convertTo(d, CV_64F);
    d = d.reshape(1, 1);
  }
  const int n = static_cast<int>(d.total());
  if (n != 0 && n != 4 && n != 5 && n != 8 && n != 12 && n != 14) {
    fail("distortion_coefficients", "has " + std::to_string(n) + " values; OpenCV takes 4, 5, 8, 12 or 14");
  }
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(d.at<double>(0, i)) || std::abs(d.at<double>(0, i)) > 1e6) {
      fail("distortion_coefficients", "value " + std::to_string(i) + " is " + text(d.at<double>(0, i)));
    }
  }
}

}  // namespace

CalibrationResult ReadCameraYaml(const std::string& path) {
  RequireReadableFile(path);  // "no such file", "permission denied", … before OpenCV says less
  CheckCameraText(path);
  try {
    cv::FileStorage fs(path, cv::FileStorage::READ);
    if (!fs.isOpened()) throw std::runtime_error(path + ": cannot be read as an OpenCV YAML/XML file");
    CalibrationResult r;
    auto need = [&](const char* key) {
      cv::FileNode n = fs[key];
      if (n.empty()) throw std::runtime_error(path + ": no '" + key + "'");
      return n;
    };
    need("image_width") >> r.image_width;
    need("image_height") >> r.image_height;
    // An !!opencv-matrix is checked before OpenCV reads it: its parser sizes the matrix from `rows`
    // and `cols` as they come (a 'rows: u' asked for gigabytes).
    auto matrix = [&](const char* key, int max_elements, cv::Mat* m) {
      const cv::FileNode n = need(key);
      const cv::FileNode rows = n["rows"], cols = n["cols"], data = n["data"];
      if (!n.isMap() || !rows.isInt() || !cols.isInt() || !data.isSeq())
        throw std::runtime_error(path + ": " + key + ": not an !!opencv-matrix with integer rows and cols and data");
      const int nr = static_cast<int>(rows), nc = static_cast<int>(cols);
      if (nr < 0 || nc < 0 || nr * static_cast<long long>(nc) > max_elements || data.size() != size_t(nr) * nc) {
        throw std::runtime_error(path + ": " + key + ": " + std::to_string(nr) + " x " + std::to_string(nc) + " with " +
                                 std::to_string(data.size()) + " values (at most " + std::to_string(max_elements) +
                                 ", and rows x cols of them)");
      }
      n >> *m;
    };
    matrix("camera_matrix", 9, &r.camera_matrix);
    matrix("distortion_coefficients", 14, &r.distortion);
    if (r.camera_matrix.rows != 3 || r.camera_matrix.cols != 3 || r.camera_matrix.type() != CV_64F)
      throw std::runtime_error(path + ": camera_matrix is not a 3 x 3 matrix of doubles");
    ValidateCamera(r, path);
    if (!fs["avg_reprojection_error"].empty()) fs["avg_reprojection_error"] >> r.avg_error_px;
    r.calibrated = true;
    return r;
  } catch (const cv::Exception& e) {  // OpenCV's parser: a message of its own, naming no file
    throw std::runtime_error(path + ": not a camera file OpenCV can parse (" + e.msg + ")");
  }
}

}  // namespace mbot::vision
