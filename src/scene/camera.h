// scene/camera.h — perspective look-at camera that may move: keyframes of
// position, target and up, interpolated linearly in scene time (the pose is
// rebuilt from them, so a camera tracking a moving object sees it sharp).
// A thin lens (lens radius > 0) moves with the camera: the ray starts on
// the lens disc, at right x up around the position, and passes through the
// pinhole ray's point on the focal plane (the plane at focal distance along
// forward), so that plane is sharp and a point at depth d is a disc of
// diameter 2 r |d - f| / d on the focal plane (docs/scene-format.md).
#pragma once
#include <cstdint>
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
  bool thinLens() const { return lensRadius_ > 0; }
  float lensRadius() const { return lensRadius_; }
  float focalDistance() const { return focalDistance_; }

  // Primary ray through raster position (x right, y down, in pixels) at
  // normalised shutter time u01, through the lens point of `lens` in
  // [0,1)^2 (the sampler's dims::kCameraLens; ignored by a pinhole).
  void generateRay(Vec2f raster, float time01, Vec2f lens, Vec3f& origin, Vec3f& direction) const;
  // The ray through the lens centre (the pinhole ray): pixel footprints.
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
  float lensRadius_ = 0.0f, focalDistance_ = 1.0f;
  Pose stillPose_{};  // a camera with one key: its pose, made once (every camera ray asks)
};

// The lens point of sample i: the pixel sampler's kCameraLens draw for a
// thin lens, not drawn at all for a pinhole (whose rays ignore it), so a
// pinhole render costs what it did before the lens existed.
template <class PixelSampler>
Vec2f lensSample(const Camera& cam, const PixelSampler& ps, uint32_t i) {
  return cam.thinLens() ? ps.lens(i) : Vec2f{0.5f, 0.5f};
}

}  // namespace tdpm
