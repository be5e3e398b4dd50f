#include "mbot/sim/sim_camera.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "mbot/vision/apriltag_detector.hpp"

namespace mbot::sim {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
// Brightness of the plain surfaces (0-255, before the light and the sensor).
constexpr float kFloor = 95.0f, kWall = 205.0f, kBackground = 150.0f;
constexpr float kCrate = 185.0f, kCrateTop = 175.0f, kCrateBottom = 60.0f;
constexpr float kTagWhite = 235.0f, kTagBlack = 25.0f;
// The light comes from this direction (world frame, horizontal) for the vertical faces.
constexpr double kLightAngle = 1.0;

float Light(double nx, double ny) {
  const double d = nx * std::cos(kLightAngle) + ny * std::sin(kLightAngle);
  return static_cast<float>(0.78 + 0.22 * std::max(0.0, d));
}

}  // namespace

// What one frame needs beside the rays: where the camera is, the walls' distance per angle, and
// each crate's pose with its tag.
struct SimCamera::Scene {
  double cx = 0, cy = 0, cz = 0, cos_t = 1, sin_t = 0;
  std::vector<float> walls;
  struct Box {
    const Crate* crate;
    double c, s;         // the crate's heading
    double p[2];         // the camera in the crate's frame (horizontal)
    cv::Rect pixels;     // where in the frame it may be seen
    const cv::Mat* tag;  // 10 × 10 tag36h11 image
    float light[4];      // +x, −x, +y, −y faces
  };
  std::vector<Box> boxes;
};

SimCamera::SimCamera(const SimCameraOptions& options) : o_(options) {
  if (o_.width < 16 || o_.height < 16 || o_.width > 8192 || o_.height > 8192)
    throw std::invalid_argument("sim camera: image size out of range (16-8192 pixels a side)");
  if (!(o_.rate_hz > 0) || !(o_.tag_size_m > 0) || !(o_.wall_height_m > 0) || !(o_.max_range_m > 0) ||
      o_.noise_stddev < 0 || o_.blur_sigma_px < 0 || o_.exposure_change < 0 || o_.exposure_change >= 1)
    throw std::invalid_argument(
        "sim camera: rate, tag size, wall height and range must be positive, noise and blur >= 0, exposure change in "
        "[0, 1)");
  if (!(o_.mount.z_m > 0 && o_.mount.z_m < o_.wall_height_m))
    throw std::invalid_argument("sim camera: the camera must be above the floor and below the walls' top");
  max_range_ = static_cast<float>(o_.max_range_m);
  if (o_.intrinsics.K == cv::Matx33d::eye())
    o_.intrinsics.K = {530, 0, o_.width / 2.0, 0, 530, o_.height / 2.0, 0, 0, 1};
  std::vector<cv::Point2f> pixels, normalised;
  pixels.reserve(static_cast<size_t>(o_.width) * o_.height);
  for (int v = 0; v < o_.height; ++v)
    for (int u = 0; u < o_.width; ++u) pixels.emplace_back(static_cast<float>(u), static_cast<float>(v));
  cv::undistortPoints(pixels, normalised, cv::Mat(o_.intrinsics.K),
                      o_.intrinsics.distortion.empty() ? cv::Mat() : o_.intrinsics.distortion);
  const cv::Matx33d R = o_.mount.Rotation();
  rays_.resize(pixels.size());
  float lo = kInf, hi = -kInf;
  for (size_t i = 0; i < pixels.size(); ++i) {
    const cv::Vec3d d = R * cv::Vec3d(normalised[i].x, normalised[i].y, 1.0);
    const double h = std::max(std::hypot(d[0], d[1]), 1e-9);
    rays_[i] = {static_cast<float>(d[0] / h),
                static_cast<float>(d[1] / h),
                static_cast<float>(d[2] / h),
                static_cast<float>(std::atan2(d[1], d[0])),
                0,
                0,
                0};
    lo = std::min(lo, rays_[i].phi);
    hi = std::max(hi, rays_[i].phi);
  }
  // Half a pixel's angle per wall column.
  phi_step_ = static_cast<float>(0.5 / std::max(o_.intrinsics.K(0, 0), 1.0));
  phi_min_ = lo - phi_step_;
  wall_columns_ = static_cast<int>(std::ceil((hi - lo) / phi_step_)) + 3;
  for (Ray& r : rays_) Complete(&r);
}

void SimCamera::Complete(Ray* r) const {
  r->column = Column(r->phi);
  const double cz = o_.mount.z_m;
  r->floor = r->slope < 0 && cz > 0 ? static_cast<float>(cz / -r->slope) : kInf;
  r->over_walls = r->slope > 0 ? static_cast<float>((o_.wall_height_m - cz) / r->slope) : kInf;
}

int SimCamera::Column(float phi) const {
  return std::clamp(static_cast<int>(std::lround((phi - phi_min_) / phi_step_)), 0, wall_columns_ - 1);
}

void SimCamera::CameraPose(const motion::Pose2D& robot, cv::Matx33d* R, cv::Vec3d* t) const {
  const double c = std::cos(robot.theta), s = std::sin(robot.theta);
  const cv::Matx33d Rz(c, -s, 0, s, c, 0, 0, 0, 1);
  *R = Rz * o_.mount.Rotation();
  *t = {robot.x + c * o_.mount.x_m - s * o_.mount.y_m, robot.y + s * o_.mount.x_m + c * o_.mount.y_m, o_.mount.z_m};
}

SimCamera::Ray SimCamera::RayAt(double u, double v) const {
  const int w = o_.width, h = o_.height;
  const int u0 = std::clamp(static_cast<int>(std::floor(u)), 0, w - 2),
            v0 = std::clamp(static_cast<int>(std::floor(v)), 0, h - 2);
  const float a = static_cast<float>(u - u0), b = static_cast<float>(v - v0);
  const Ray& r00 = rays_[static_cast<size_t>(v0) * w + u0];
  const Ray& r10 = rays_[static_cast<size_t>(v0) * w + u0 + 1];
  const Ray& r01 = rays_[static_cast<size_t>(v0 + 1) * w + u0];
  const Ray& r11 = rays_[static_cast<size_t>(v0 + 1) * w + u0 + 1];
  auto mix = [&](float Ray::*f) {
    return (1 - a) * (1 - b) * (r00.*f) + a * (1 - b) * (r10.*f) + (1 - a) * b * (r01.*f) + a * b * (r11.*f);
  };
  // The mix of the 3-D directions (x, y, slope), made horizontally unit again.
  Ray r{mix(&Ray::x), mix(&Ray::y), mix(&Ray::slope), mix(&Ray::phi), 0, 0, 0};
  const float n = std::sqrt(r.x * r.x + r.y * r.y);
  r.x /= n, r.y /= n, r.slope /= n;
  Complete(&r);
  return r;
}

// The floor, the walls or the background: the brightness and the distance (horizontal) of the hit.
inline float SimCamera::Base(const Scene& sc, const Ray& r, float* value) const {
  const float wall = sc.walls[r.column];
  if (r.floor < wall) {
    *value = kFloor;
    return r.floor;
  }
  if (wall < max_range_ && wall <= r.over_walls) {
    *value = kWall * (1.0f - 0.03f * std::min(wall, 5.0f));
    return wall;
  }
  *value = r.floor < kInf ? kFloor : kBackground;
  return r.floor;
}

// Crate k along the ray, if it is nearer than *best: updates *best and *hit.
inline void SimCamera::CrateHit(const Scene& sc, size_t k, const Ray& r, float* best, Hit* hit) const {
  const Scene::Box& b = sc.boxes[k];
  const Crate& c = *b.crate;
  const double wx = sc.cos_t * r.x - sc.sin_t * r.y, wy = sc.sin_t * r.x + sc.cos_t * r.y;
  const double u[2] = {b.c * wx + b.s * wy, -b.s * wx + b.c * wy};
  const double half[2] = {0.5 * c.width_m, 0.5 * c.depth_m};
  double t0 = 0, t1 = kInf;
  int axis = -1;
  for (int a = 0; a < 2; ++a) {
    if (std::abs(u[a]) < 1e-12) {
      if (std::abs(b.p[a]) > half[a]) return;
      continue;
    }
    const double inv = 1.0 / u[a];
    double ta = (-half[a] - b.p[a]) * inv, tb = (half[a] - b.p[a]) * inv;
    if (ta > tb) std::swap(ta, tb);
    if (ta > t0) t0 = ta, axis = a;
    t1 = std::min(t1, tb);
    if (t0 > t1) return;
  }
  if (axis < 0 || t0 >= *best) return;  // axis < 0: the camera is above the footprint
  const double h = sc.cz + r.slope * t0;
  if (h >= c.z_m && h <= c.top_m()) {
    // A vertical face: which one, and where on it.
    const int side = u[axis] > 0 ? -1 : 1;  // the face's outward normal is side · e_axis
    const double q[2] = {b.p[0] + t0 * u[0], b.p[1] + t0 * u[1]};
    const double nx = axis == 0 ? side : 0.0, ny = axis == 1 ? side : 0.0;
    const double across = -ny * q[0] + nx * q[1];  // along the face, to the right seen from outside
    const double cell = o_.tag_size_m / 8.0, full = 10.0 * cell;
    const double centre = c.z_m + 0.5 * c.height_m;
    const double col_f = (across + 0.5 * full) / cell, row_f = (centre + 0.5 * full - h) / cell;
    *best = static_cast<float>(t0);
    hit->surface = static_cast<int>(k);
    const float light = b.light[axis * 2 + (side > 0 ? 0 : 1)];
    hit->tag = col_f >= 0 && col_f < 10 && row_f >= 0 && row_f < 10;
    if (hit->tag) {
      hit->value =
          light * (b.tag->at<uint8_t>(static_cast<int>(row_f), static_cast<int>(col_f)) > 127 ? kTagWhite : kTagBlack);
    } else {
      hit->value = light * kCrate;
    }
  } else if (h > c.top_m() && r.slope < 0) {
    const double t = (sc.cz - c.top_m()) / -r.slope;
    if (t <= t1 && t < *best) *best = static_cast<float>(t), *hit = {kCrateTop, static_cast<int>(k), false};
  } else if (h < c.z_m && r.slope > 0) {
    const double t = (c.z_m - sc.cz) / r.slope;
    if (t <= t1 && t < *best) *best = static_cast<float>(t), *hit = {kCrateBottom, static_cast<int>(k), false};
  }
}

void SimCamera::Shade(const Scene& sc, const Ray& r, Hit* hit) const {
  *hit = Hit{};
  float best = Base(sc, r, &hit->value);
  for (size_t k = 0; k < sc.boxes.size(); ++k) CrateHit(sc, k, r, &best, hit);
}

cv::Mat SimCamera::RenderFloat(const World& world, const motion::Pose2D& robot) const {
  Scene sc;
  cv::Matx33d R;
  cv::Vec3d t;
  CameraPose(robot, &R, &t);
  sc.cx = t[0], sc.cy = t[1], sc.cz = t[2];
  sc.cos_t = std::cos(robot.theta), sc.sin_t = std::sin(robot.theta);
  sc.walls.resize(wall_columns_);
  for (int i = 0; i < wall_columns_; ++i) {
    const double phi = phi_min_ + i * phi_step_;
    const double d = world.RaycastWalls(sc.cx, sc.cy, robot.theta + phi, o_.max_range_m);
    sc.walls[i] = static_cast<float>(d <= 0.0 ? 0.0 : d);
  }
  const cv::Rect frame(0, 0, o_.width, o_.height);
  cv::Rect any_crate;  // where crates may be seen
  for (const Crate& c : world.crates()) {
    const double dx = c.pose.x - sc.cx, dy = c.pose.y - sc.cy;
    if (c.DistanceTo(sc.cx, sc.cy) <= 0.0 || std::hypot(dx, dy) > o_.max_range_m) continue;
    Scene::Box b;
    b.crate = &c;
    b.c = std::cos(c.pose.theta), b.s = std::sin(c.pose.theta);
    b.p[0] = b.c * -dx + b.s * -dy, b.p[1] = -b.s * -dx + b.c * -dy;
    // Its pixels: the box round the projections of its eight corners (the whole frame when a corner
    // is behind the camera).
    std::vector<cv::Point3d> corners;
    bool behind = false;
    for (const double z : {c.z_m, c.top_m()}) {
      for (const auto& [x, y] : c.Outline(1.0)) {
        const cv::Vec3d in_camera = R.t() * (cv::Vec3d(x, y, z) - t);
        behind = behind || in_camera[2] < 0.01;
        corners.emplace_back(in_camera[0], in_camera[1], in_camera[2]);
      }
    }
    if (behind) {
      b.pixels = frame;
    } else {
      std::vector<cv::Point2d> projected;
      cv::projectPoints(corners, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), cv::Mat(o_.intrinsics.K),
                        o_.intrinsics.distortion.empty() ? cv::Mat() : o_.intrinsics.distortion, projected);
      double u0 = kInf, v0 = kInf, u1 = -kInf, v1 = -kInf;
      for (const cv::Point2d& q : projected) {
        u0 = std::min(u0, q.x), v0 = std::min(v0, q.y), u1 = std::max(u1, q.x), v1 = std::max(v1, q.y);
      }
      const double lo = -1e6, hi = 1e6;  // keep the casts in range
      const cv::Rect box(cv::Point(static_cast<int>(std::clamp(std::floor(u0), lo, hi)) - 2,
                                   static_cast<int>(std::clamp(std::floor(v0), lo, hi)) - 2),
                         cv::Point(static_cast<int>(std::clamp(std::ceil(u1), lo, hi)) + 3,
                                   static_cast<int>(std::clamp(std::ceil(v1), lo, hi)) + 3));
      b.pixels = box & frame;
    }
    if (b.pixels.empty()) continue;
    any_crate = any_crate.empty() ? b.pixels : (any_crate | b.pixels);
    auto it = tags_.find(c.id);
    if (it == tags_.end()) it = tags_.emplace(c.id, vision::TagImage("tag36h11", c.id, 1)).first;
    b.tag = &it->second;
    b.light[0] = Light(b.c, b.s), b.light[1] = Light(-b.c, -b.s);
    b.light[2] = Light(-b.s, b.c), b.light[3] = Light(b.s, -b.c);
    sc.boxes.push_back(b);
  }

  // One ray per pixel: the floor and walls everywhere, then each crate over its pixels.
  cv::Mat image(o_.height, o_.width, CV_32F), depth(o_.height, o_.width, CV_32F);
  for (int v = 0; v < o_.height; ++v) {
    float* row = image.ptr<float>(v);
    float* d = depth.ptr<float>(v);
    const Ray* rays = &rays_[static_cast<size_t>(v) * o_.width];
    for (int u = 0; u < o_.width; ++u) d[u] = Base(sc, rays[u], &row[u]);
  }
  if (sc.boxes.empty()) return image;
  cv::Mat surface(o_.height, o_.width, CV_32S, cv::Scalar(-1)), on_tag(o_.height, o_.width, CV_8U, cv::Scalar(0));
  for (size_t k = 0; k < sc.boxes.size(); ++k) {
    const cv::Rect& box = sc.boxes[k].pixels;
    for (int v = box.y; v < box.br().y; ++v) {
      for (int u = box.x; u < box.br().x; ++u) {
        Hit h{image.at<float>(v, u), surface.at<int>(v, u), on_tag.at<uint8_t>(v, u) != 0};
        CrateHit(sc, k, rays_[static_cast<size_t>(v) * o_.width + u], &depth.at<float>(v, u), &h);
        image.at<float>(v, u) = h.value, surface.at<int>(v, u) = h.surface, on_tag.at<uint8_t>(v, u) = h.tag;
      }
    }
  }
  // Area sampling where a crate's pixels change: its outline (a neighbour sees another surface) and
  // its tag's cell edges (a neighbour on the same face differs in brightness). Flat areas keep their
  // one ray: area sampling would give the same value.
  cv::Mat out = image.clone();
  const int w = o_.width, h = o_.height;
  for (int v = any_crate.y; v < any_crate.br().y; ++v) {
    const int* id = surface.ptr<int>(v);
    const int* up = surface.ptr<int>(std::max(v - 1, 0));
    const int* down = surface.ptr<int>(std::min(v + 1, h - 1));
    const float* val = image.ptr<float>(v);
    const float* val_up = image.ptr<float>(std::max(v - 1, 0));
    const float* val_down = image.ptr<float>(std::min(v + 1, h - 1));
    const uint8_t* tag = on_tag.ptr<uint8_t>(v);
    float* o = out.ptr<float>(v);
    for (int u = any_crate.x; u < any_crate.br().x; ++u) {
      const int l = std::max(u - 1, 0), r = std::min(u + 1, w - 1);
      const bool outline = id[l] != id[u] || id[r] != id[u] || up[u] != id[u] || down[u] != id[u];
      const bool cell_edge =
          tag[u] && (val[l] != val[u] || val[r] != val[u] || val_up[u] != val[u] || val_down[u] != val[u]);
      if (!outline && !cell_edge) continue;
      float sum = 0;
      Hit hit;
      for (const double j : {-0.25, 0.25}) {
        for (const double i : {-0.25, 0.25}) {
          Shade(sc, RayAt(u + i, v + j), &hit);
          sum += hit.value;
        }
      }
      o[u] = 0.25f * sum;
    }
  }
  return out;
}

cv::Mat SimCamera::RenderScene(const World& world, const motion::Pose2D& robot) const {
  cv::Mat out;
  RenderFloat(world, robot).convertTo(out, CV_8U);
  return out;
}

cv::Mat SimCamera::Render(const World& world, const motion::Pose2D& robot, std::mt19937_64& rng) const {
  cv::Mat image = RenderFloat(world, robot);
  if (o_.exposure_change > 0) {
    std::uniform_real_distribution<double> gain(1.0 - o_.exposure_change, 1.0 + o_.exposure_change);
    image *= gain(rng);
  }
  if (o_.blur_sigma_px > 0) cv::GaussianBlur(image, image, cv::Size(0, 0), o_.blur_sigma_px);
  if (o_.noise_stddev > 0) {
    cv::Mat noise(image.size(), CV_32F);
    cv::RNG cv_rng(rng());
    cv_rng.fill(noise, cv::RNG::NORMAL, 0.0, o_.noise_stddev);
    image += noise;
  }
  cv::Mat out;
  image.convertTo(out, CV_8U);  // rounds and saturates
  return out;
}

}  // namespace mbot::sim
