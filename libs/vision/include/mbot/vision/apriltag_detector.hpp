// AprilTag detection with the AprilRobotics reference detector (Debian libapriltag-dev 3.3): the
// family, decimation, blur, edge refinement, sharpening and threads of the detector are options; a
// detection carries the id, the four corners in the library's order and pixel convention, the
// centre, the Hamming distance corrected and the decision margin.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace mbot::vision {

struct TagDetectorOptions {
  std::string family = "tag36h11";  // one of TagFamilies(); the ROS 2 MBot's are tagCustom48h12
  // Bit errors the decoder corrects; -1: the library's default for add_family (2), or 1 for a family
  // of more than 10,000 codes (tagCustom48h12, tagStandard52h13, tagCircle49h12), whose 2-bit table
  // takes seconds and gigabytes to build (7.5 s for tagCustom48h12, here); 2 or 3 there is refused.
  int max_bits_corrected = -1;
  double decimate = 2.0;     // quad_decimate: detect quads on an image this much smaller
  double blur_sigma = 0.0;   // quad_sigma: Gaussian blur before quads (0: none)
  bool refine_edges = true;  // snap the quad's edges to strong gradients
  double decode_sharpening = 0.25;
  int threads = 1;
};

struct TagDetection {
  int id = -1;
  int hamming = 0;                     // bits corrected
  double margin = 0.0;                 // decision margin (higher: surer)
  std::array<cv::Point2d, 4> corners;  // the library's order (counter-clockwise in the image)
  cv::Point2d center;
  std::array<double, 9> homography{};  // tag frame (-1..1) → image, row-major, as the library gives it
};

// The families the detector knows: every family of Debian's libapriltag 3.3.
std::vector<std::string> TagFamilies();

// The tag as the library draws it (its total_width cells, white border included), each cell
// `pixels_per_cell` pixels: for printing, and for the simulator's crates. Throws
// std::invalid_argument naming an unknown family or an id outside it.
cv::Mat TagImage(const std::string& family, int id, int pixels_per_cell);

// `image` in colour with each tag's outline (its first edge, corner 0 to 1, in red) and id drawn.
cv::Mat DrawTags(const cv::Mat& image, const std::vector<TagDetection>& tags);

class TagDetector {
 public:
  // Throws std::invalid_argument naming an unknown family or an option out of range.
  explicit TagDetector(const TagDetectorOptions& options);
  ~TagDetector();
  TagDetector(const TagDetector&) = delete;
  TagDetector& operator=(const TagDetector&) = delete;

  // Detections in `image` (8-bit, grey or colour), sorted by id and then by centre (x, y).
  std::vector<TagDetection> Detect(const cv::Mat& image) const;
  const TagDetectorOptions& options() const { return options_; }

 private:
  struct Impl;
  TagDetectorOptions options_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mbot::vision
