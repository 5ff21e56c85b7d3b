// scene/camera.cpp — camera pose interpolation and ray generation.
#include "scene/camera.h"

#include <cmath>

#include "sampling/warp.h"

namespace tdpm {

Camera::Camera(const scene::CameraDesc& d)
    : shutter_{d.shutterOpen, d.shutterClose}, width_(d.width), height_(d.height),
      lensRadius_(d.lensRadius), focalDistance_(d.focalDistance) {
  tanHalfFov_ = std::tan(0.5f * d.fovDegrees * kPi / 180.0f);
  aspect_ = float(d.width) / float(d.height);
  if (d.motion.empty()) keys_ = {{d.shutterOpen, d.position, d.target, d.up}};
  else keys_ = d.motion;
  if (keys_.size() == 1) stillPose_ = interpolatePose(0.0f);
}

Camera::Pose Camera::poseAt(float time01) const {
  return keys_.size() == 1 ? stillPose_ : interpolatePose(time01);
}

Camera::Pose Camera::interpolatePose(float time01) const {
  const scene::CameraKeyframe* a = &keys_.front();
  const scene::CameraKeyframe* b = a;
  float s = 0;
  float t = shutter_.fromNormalized(time01);
  if (keys_.size() > 1) {
    if (t >= keys_.back().time) { a = b = &keys_.back(); }
    else if (t > keys_.front().time) {
      size_t i = 1;
      while (keys_[i].time < t) ++i;
      a = &keys_[i - 1];
      b = &keys_[i];
      s = (t - a->time) / (b->time - a->time);
    }
  }
  Pose p;
  p.position = lerp(a->position, b->position, s);
  Vec3f target = lerp(a->target, b->target, s);
  Vec3f up = lerp(a->up, b->up, s);
  p.forward = normalize(target - p.position);
  p.right = normalize(cross(p.forward, up));
  p.up = cross(p.right, p.forward);
  return p;
}

void Camera::generateRay(Vec2f raster, float time01, Vec3f& origin, Vec3f& direction) const {
  Pose p = poseAt(time01);
  float x = (2.0f * raster.x / float(width_) - 1.0f) * tanHalfFov_ * aspect_;
  float y = (1.0f - 2.0f * raster.y / float(height_)) * tanHalfFov_;
  origin = p.position;
  direction = normalize(p.forward + p.right * x + p.up * y);
}

void Camera::generateRay(Vec2f raster, float time01, Vec2f lens, Vec3f& origin, Vec3f& direction) const {
  if (lensRadius_ <= 0) return generateRay(raster, time01, origin, direction);
  Pose p = poseAt(time01);
  float x = (2.0f * raster.x / float(width_) - 1.0f) * tanHalfFov_ * aspect_;
  float y = (1.0f - 2.0f * raster.y / float(height_)) * tanHalfFov_;
  // The pinhole direction has forward component 1, so scaling it by the
  // focal distance lands on the focal plane (pbrt's thin lens, in world space).
  Vec3f focus = (p.forward + p.right * x + p.up * y) * focalDistance_;
  Vec2f l = squareToConcentricDisk(lens);
  Vec3f offset = p.right * (l.x * lensRadius_) + p.up * (l.y * lensRadius_);
  origin = p.position + offset;
  direction = normalize(focus - offset);
}

bool Camera::project(Vec3f w, float time01, Vec2f& raster) const {
  Pose p = poseAt(time01);
  Vec3f d = w - p.position;
  float z = dot(d, p.forward);
  if (z <= 0) return false;
  float x = dot(d, p.right) / (z * tanHalfFov_ * aspect_);
  float y = dot(d, p.up) / (z * tanHalfFov_);
  raster = {(x + 1.0f) * 0.5f * float(width_), (1.0f - y) * 0.5f * float(height_)};
  return true;
}

}  // namespace tdpm
