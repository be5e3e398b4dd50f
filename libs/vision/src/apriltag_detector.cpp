#include "mbot/vision/apriltag_detector.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "mbot/vision/images.hpp"

extern "C" {
#include <apriltag.h>
#include <tag16h5.h>
#include <tag25h9.h>
#include <tag36h11.h>
#include <tagCircle21h7.h>
#include <tagCircle49h12.h>
#include <tagCustom48h12.h>
#include <tagStandard41h12.h>
#include <tagStandard52h13.h>
#include <common/image_u8.h>
#include <common/matd.h>
}

namespace mbot::vision {

namespace {

struct Family {
  const char* name;
  apriltag_family_t* (*create)();
  void (*destroy)(apriltag_family_t*);
};

const Family kFamilies[] = {{"tag36h11", tag36h11_create, tag36h11_destroy},
                            {"tag25h9", tag25h9_create, tag25h9_destroy},
                            {"tag16h5", tag16h5_create, tag16h5_destroy},
                            {"tagStandard41h12", tagStandard41h12_create, tagStandard41h12_destroy},
                            {"tagStandard52h13", tagStandard52h13_create, tagStandard52h13_destroy},
                            {"tagCircle21h7", tagCircle21h7_create, tagCircle21h7_destroy},
                            {"tagCircle49h12", tagCircle49h12_create, tagCircle49h12_destroy},
                            // the ROS 2 MBot's tags (5.4 cm, through apriltag_ros)
                            {"tagCustom48h12", tagCustom48h12_create, tagCustom48h12_destroy}};

constexpr uint32_t kLargeFamilyCodes = 10000;

const Family& FindFamily(const std::string& name) {
  std::string known;
  for (const Family& f : kFamilies) {
    if (name == f.name) return f;
    known += (known.empty() ? "" : ", ") + std::string(f.name);
  }
  throw std::invalid_argument("tag family '" + name + "' is not one of: " + known);
}

}  // namespace

std::vector<std::string> TagFamilies() {
  std::vector<std::string> names;
  for (const Family& f : kFamilies) names.emplace_back(f.name);
  return names;
}

cv::Mat TagImage(const std::string& family, int id, int pixels_per_cell) {
  const Family& f = FindFamily(family);
  apriltag_family_t* fam = f.create();
  if (id < 0 || static_cast<uint32_t>(id) >= fam->ncodes || pixels_per_cell < 1) {
    const uint32_t n = fam->ncodes;
    f.destroy(fam);
    throw std::invalid_argument(family + ": id " + std::to_string(id) + " outside 0.." + std::to_string(n - 1) +
                                " (or pixels_per_cell < 1)");
  }
  image_u8_t* im = apriltag_to_image(fam, id);
  cv::Mat cells(im->height, im->width, CV_8UC1, im->buf, im->stride);
  cv::Mat out;
  cv::resize(cells, out, cv::Size(), pixels_per_cell, pixels_per_cell, cv::INTER_NEAREST);
  image_u8_destroy(im);
  f.destroy(fam);
  return out;
}

struct TagDetector::Impl {
  apriltag_family_t* family = nullptr;
  void (*destroy_family)(apriltag_family_t*) = nullptr;
  apriltag_detector_t* detector = nullptr;
  ~Impl() {  // also when the constructor throws
    if (detector) apriltag_detector_destroy(detector);
    if (family) destroy_family(family);
  }
};

TagDetector::TagDetector(const TagDetectorOptions& o) : options_(o), impl_(std::make_unique<Impl>()) {
  const Family& f = FindFamily(o.family);
  impl_->family = f.create();
  impl_->destroy_family = f.destroy;
  if (!(o.decimate >= 1.0)) throw std::invalid_argument("tag detector: decimate must be >= 1");
  if (o.threads < 1) throw std::invalid_argument("tag detector: threads must be >= 1");
  if (o.max_bits_corrected < -1 || o.max_bits_corrected > 3)
    throw std::invalid_argument("tag detector: max_bits_corrected must be 0..3 (or -1: the family's default)");
  const bool large = impl_->family->ncodes > kLargeFamilyCodes;
  if (large && o.max_bits_corrected > 1) {
    throw std::invalid_argument("tag detector: " + o.family + " has " + std::to_string(impl_->family->ncodes) +
                                " codes; correcting " + std::to_string(o.max_bits_corrected) +
                                " bits needs a table of gigabytes: max_bits_corrected must be 0 or 1");
  }
  const int bits = o.max_bits_corrected >= 0 ? o.max_bits_corrected : large ? 1 : 2;
  impl_->detector = apriltag_detector_create();
  apriltag_detector_add_family_bits(impl_->detector, impl_->family, bits);
  impl_->detector->quad_decimate = static_cast<float>(o.decimate);
  impl_->detector->quad_sigma = static_cast<float>(o.blur_sigma);
  impl_->detector->refine_edges = o.refine_edges;
  impl_->detector->decode_sharpening = o.decode_sharpening;
  impl_->detector->nthreads = o.threads;
}

TagDetector::~TagDetector() = default;

std::vector<TagDetection> TagDetector::Detect(const cv::Mat& image) const {
  if (image.empty() || image.depth() != CV_8U) throw std::invalid_argument("tag detector: needs an 8-bit image");
  cv::Mat gray;
  if (image.channels() == 1) {
    gray = image.isContinuous() ? image : image.clone();
  } else {
    cv::cvtColor(image, gray, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  }
  // The reference library reads past a decimated image of fewer than a few rows (a 16 x 1 image
  // crashes it); no tag fits in one that small anyway.
  const int min_side = static_cast<int>(std::ceil(8 * options_.decimate));
  if (gray.cols < min_side || gray.rows < min_side) return {};
  image_u8_t im{gray.cols, gray.rows, static_cast<int32_t>(gray.step[0]), gray.data};
  zarray_t* found = apriltag_detector_detect(impl_->detector, &im);
  std::vector<TagDetection> out;
  for (int i = 0; i < zarray_size(found); ++i) {
    apriltag_detection_t* d = nullptr;
    zarray_get(found, i, &d);
    TagDetection t;
    t.id = d->id;
    t.hamming = d->hamming;
    t.margin = d->decision_margin;
    for (int k = 0; k < 4; ++k) t.corners[k] = {d->p[k][0], d->p[k][1]};
    t.center = {d->c[0], d->c[1]};
    for (int k = 0; k < 9; ++k) t.homography[k] = MATD_EL(d->H, k / 3, k % 3);
    out.push_back(t);
  }
  apriltag_detections_destroy(found);
  std::sort(out.begin(), out.end(), [](const TagDetection& a, const TagDetection& b) {
    if (a.id != b.id) return a.id < b.id;
    if (a.center.x != b.center.x) return a.center.x < b.center.x;
    return a.center.y < b.center.y;
  });
  return out;
}

cv::Mat DrawTags(const cv::Mat& image, const std::vector<TagDetection>& tags) {
  cv::Mat shown = ToBgr(image);
  for (const TagDetection& t : tags) {
    for (int k = 0; k < 4; ++k) {
      cv::line(shown, t.corners[k], t.corners[(k + 1) % 4], k == 0 ? cv::Scalar(0, 0, 255) : cv::Scalar(0, 200, 0), 1,
               cv::LINE_AA);
    }
    cv::putText(shown, std::to_string(t.id), t.center, cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(255, 0, 0), 1,
                cv::LINE_AA);
  }
  return shown;
}

}  // namespace mbot::vision
