// scene/parse_animation.cpp — the "animation" block: fps > 0, frames >= 1,
// shutter_angle in (0, 360] (default 180). The keyframe clock check (every
// keyframe inside [0, frames / fps]) is parse.cpp's, which reads keyframes
// against the camera's shutter, here the whole timeline.
#include "scene/parse_animation.h"

#include <cmath>
#include <limits>

namespace tdpm::scene {

AnimationDesc readAnimation(const detail::Node& n) {
  n.expectObject({"fps", "frames", "shutter_angle"});
  AnimationDesc a;
  detail::Node fps = n.required("fps");
  a.fps = fps.number();
  fps.require(a.fps > 0, "fps must be > 0, got " + detail::formatNumber(a.fps));
  detail::Node frames = n.required("frames");
  int64_t count = frames.integer();
  frames.require(count >= 1 && count <= kMaxAnimationFrames,
                 "frames must be between 1 and " + std::to_string(kMaxAnimationFrames) + ", got " +
                     std::to_string(count));
  a.frames = int(count);
  if (n.has("shutter_angle")) {
    detail::Node angle = n.member("shutter_angle");
    a.shutterAngle = angle.number();
    angle.require(a.shutterAngle > 0 && a.shutterAngle <= 360,
                  "shutter_angle must be in (0, 360] degrees, got " + detail::formatNumber(a.shutterAngle));
  }
  // The timeline and a frame's shutter must be finite, non-zero floats.
  float duration = float(a.duration()), shutter = float(a.shutterLength());
  n.require(std::isfinite(duration) && shutter >= std::numeric_limits<float>::min(),
            "fps " + detail::formatNumber(a.fps) + " with " + std::to_string(a.frames) +
                " frames gives a timeline of " + detail::formatNumber(a.duration()) + " s and a shutter of " +
                detail::formatNumber(a.shutterLength()) + " s, outside the float range");
  return a;
}

}  // namespace tdpm::scene
