// The simulated MBot's camera (Heavy Lift): 8-bit grey frames of what a camera at its mounting pose
// on the robot sees in the World — the floor, the walls (vertical, wall_height_m high) and the
// crates (boxes, with the tag36h11 tag of their id printed upright and centred on each vertical
// face, tag_size_m the black square's side), each pixel the nearest surface along its own ray, so a
// wall or a crate in front hides what is behind it, and a crate on the tines hides what is below it.
//
// Rays come from the camera model (intrinsics and distortion, e.g. a camera.yaml): each pixel's
// ray is its undistorted direction, so the image is distorted as the real lens would distort it
// and the tags appear under their true projection. Pixels on a crate's outline or a tag's cell edge
// are the mean of 2 × 2 rays (edges anti-aliased as a real sensor's area sampling makes them); the
// rest use one ray. The camera must be below the walls' top.
// Walls and floor are plain; each crate face and wall is lit by its direction to a fixed light.
// Then the sensor: an exposure gain drawn per frame, Gaussian blur, Gaussian noise.
//
// Speed: the walls are found per frame by one ray cast per column of angles (all surfaces are
// vertical or horizontal, and the robot only moves in the plane, so each pixel's direction in the
// robot frame is fixed and computed once); a crate is cast only over the box round its projected
// corners.
#pragma once

#include <cstdint>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "mbot/motion/pose2d.hpp"
#include "mbot/sim/world.hpp"
#include "mbot/vision/tag_observer.hpp"

namespace mbot::sim {

struct SimCameraOptions {
  bool enabled = false;
  int width = 640, height = 480;
  vision::CameraIntrinsics intrinsics;  // default: fx = fy = 530, centred (set in the constructor when K is identity)
  vision::CameraMount mount;            // on the robot (x ahead, y left, z up; pitch down positive)
  double rate_hz = 15.0;
  double tag_size_m = 0.054;    // the black square's side (8 of the tag image's 10 cells)
  double wall_height_m = 0.30;  // botlab arena walls
  double max_range_m = 10.0;    // farther than this is background
  // The sensor.
  double noise_stddev = 2.0;      // grey levels
  double blur_sigma_px = 0.6;     // 0: none
  double exposure_change = 0.10;  // the gain of each frame is uniform in [1 − this, 1 + this]
};

class SimCamera {
 public:
  // Throws std::invalid_argument for a size or rate out of range.
  explicit SimCamera(const SimCameraOptions& options);

  // The frame a camera on a robot at `robot` (world frame) sees; `rng` draws the sensor's noise.
  cv::Mat Render(const World& world, const motion::Pose2D& robot, std::mt19937_64& rng) const;
  // The same without the sensor (no exposure change, blur or noise): the scene as rays see it.
  cv::Mat RenderScene(const World& world, const motion::Pose2D& robot) const;

  const SimCameraOptions& options() const { return o_; }
  // The camera's pose in the world (OpenCV frame → world): rotation and position, for tests and
  // benchmarks that compare a tag's estimated pose with the truth.
  void CameraPose(const motion::Pose2D& robot, cv::Matx33d* R, cv::Vec3d* t) const;

 private:
  struct Ray {
    float x, y;   // horizontal direction in the robot frame (unit)
    float slope;  // rise per horizontal metre
    float phi;    // atan2(y, x)
    int column;   // its index into the wall distances
    // Fixed by the mount (the camera's height does not change): the horizontal distance at which
    // the ray meets the floor (+inf when it does not go down), and beyond which it passes over the
    // walls (+inf when it does not go up).
    float floor, over_walls;
  };
  struct Hit {
    float value = 0;   // brightness before the sensor, 0-255
    int surface = -1;  // the crate's index, -1 for floor, walls and background
    bool tag = false;  // on a crate's tag
  };
  struct Scene;                         // one frame's camera position, wall distances, crate tags (sim_camera.cpp)
  Ray RayAt(double u, double v) const;  // interpolated between the pixel rays
  void Shade(const Scene& scene, const Ray& r, Hit* hit) const;
  float Base(const Scene& scene, const Ray& r, float* value) const;
  void CrateHit(const Scene& scene, size_t k, const Ray& r, float* best, Hit* hit) const;
  int Column(float phi) const;
  void Complete(Ray* r) const;  // column, floor and over_walls from the direction
  cv::Mat RenderFloat(const World& world, const motion::Pose2D& robot) const;

  SimCameraOptions o_;
  std::vector<Ray> rays_;  // per pixel, row-major
  float phi_min_ = 0, phi_step_ = 1;
  int wall_columns_ = 0;
  float max_range_ = 10;
  mutable std::map<int, cv::Mat> tags_;  // tag36h11 images by id, 10 × 10, drawn when first seen
};

}  // namespace mbot::sim
