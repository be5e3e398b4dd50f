// Rigid transforms as tf2 keeps them, for the lidar's mount: the tree of /tf_static (parent →
// child), walked to give one frame's pose in another.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <utility>

#include "mbot/ros2/messages.hpp"

namespace mbot::ros2 {

// a ∘ b: b expressed in a's frame, mapped to a's parent.
Transform Compose(const Transform& a, const Transform& b);
Transform Inverse(const Transform& t);
Vector3 Rotate(const Quaternion& q, const Vector3& v);

// The transforms of /tf_static (parent → child, as 3D rigid transforms): what a frame's pose is in
// another, by walking the tree. A loop or a frame with two parents is refused with a warning.
class StaticTransforms {
 public:
  // Adds the message's transforms; returns a description of each one refused ("" when none).
  std::string Add(const TFMessage& message);
  // The transform that maps coordinates in `frame` to `base` (the pose of `frame` in `base`), or
  // nullopt when the tree does not connect them.
  std::optional<Transform> Lookup(const std::string& base, const std::string& frame) const;
  bool empty() const { return parent_.empty(); }

 private:
  std::map<std::string, std::pair<std::string, Transform>> parent_;  // child → (parent, child in parent)
};

}  // namespace mbot::ros2
