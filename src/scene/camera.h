// scene/camera.h — perspective look-at camera that may move: keyframes of
// position, target and up, interpolated linearly in scene time (the pose is
// rebuilt from them, so a camera tracking a moving object sees it sharp).
#pragma once
#include <vector>

#include "math/vec.h"
#include "motion/shutter.h"
#include "scene/description.h"

namespace tdpm {

class Camera {
 public:
  Camera() = default;
  Camera(const scene::CameraDesc& desc);

  int width() const { return width_; }
  int height() const { return height_; }
  const Shutter& shutter() const { return shutter_; }
  bool moving() const { return keys_.size() > 1; }

  // Primary ray through raster position (x right, y down, in pixels) at
  // normalised shutter time u01.
  void generateRay(Vec2f raster, float time01, Vec3f& origin, Vec3f& direction) const;
  // Raster position of a world point at time u01; false if behind the camera.
  bool project(Vec3f p, float time01, Vec2f& raster) const;

 private:
  struct Pose { Vec3f position, forward, right, up; };
  Pose poseAt(float time01) const;
  Pose interpolatePose(float time01) const;

  std::vector<scene::CameraKeyframe> keys_;
  Shutter shutter_;
  int width_ = 1, height_ = 1;
  float tanHalfFov_ = 1.0f, aspect_ = 1.0f;
  Pose stillPose_{};  // a camera with one key: its pose, made once (every camera ray asks)
};

}  // namespace tdpm
