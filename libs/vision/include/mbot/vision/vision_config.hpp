// INI parsing for the vision options (one function per options struct). The algorithm headers never
// see the INI reader; only the application calls these.
#pragma once

#include "mbot/vision/apriltag_detector.hpp"
#include "mbot/vision/tag_observer.hpp"

namespace mbot::config {
class Section;
}

namespace mbot::vision {

// Keys family, max_bits_corrected, decimate, blur_sigma, refine_edges, decode_sharpening, threads.
TagDetectorOptions ParseTagDetectorOptions(config::Section& section, const TagDetectorOptions& defaults = {});
// The camera's mounting pose: camera_x_m, camera_y_m, camera_z_m, camera_roll_deg, camera_pitch_deg,
// camera_yaw_deg.
CameraMount ParseCameraMount(config::Section& section, const CameraMount& defaults = {});
// The detector's keys, and tag_size_m, tag_ids, pose_method and the mounting pose
// (ParseCameraMount). Throws config::ConfigError naming section and key.
TagObserverOptions ParseTagObserverOptions(config::Section& section, const TagObserverOptions& defaults = {});

}  // namespace mbot::vision
