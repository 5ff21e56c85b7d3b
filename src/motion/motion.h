// motion/motion.h — keyframed rigid motion as the renderer sees it.
//
// The keyframes of a scene file (TRS poses: translation and scale linear,
// rotation slerp) are resampled once into N equally spaced time steps over
// the shutter, and between steps the 3x4 matrices are blended component-wise.
// That blend is exactly what Embree does with time-step vertex buffers, so
// Motion::at(t) is *the* definition of where an object is at time t: the
// ray tracer, swept bounds, light emission and tests all agree with it.
//
// Step count: the smallest N (<= 128 intervals, Embree allows 129 steps) that
// puts every keyframe time on a step (so translation and scale are exact),
// and keeps each step's rotation below kMaxStepRotation (the chord of a
// rotation blended linearly deviates from the arc by 1 - cos(angle/2)).
#pragma once
#include <vector>

#include "math/bounds.h"
#include "math/transform.h"
#include "motion/shutter.h"

namespace tdpm {

struct MotionKey {
  float time = 0;
  Vec3f translate{0, 0, 0};
  Quaternion rotate{};
  Vec3f scale{1, 1, 1};
};

class Motion {
 public:
  static constexpr int kMaxSteps = 129;             // Embree's RTC_MAX_TIME_STEP_COUNT
  static constexpr float kMaxStepRotation = 0.035f;  // radians (2 degrees): chord error < 1.6e-4 of the radius

  Motion() : steps_{Affine3f::identity()} {}
  // A placement that never moves.
  static Motion still(const Affine3f& placement);
  // Keyframed motion on top of a placement (placement.time is ignored):
  //   world(t) = Translate(P.t + k.t(t)) * Rotate(k.r(t) * P.r) * Scale(k.s(t) * P.s)
  // i.e. keyframe translations move the object along world axes, keyframe
  // rotations and scales act about the object's own placed centre (not the
  // world origin). keys: >= 2, times strictly increasing inside the
  // shutter (the parser guarantees it).
  static Motion keyframed(const MotionKey& placement, const std::vector<MotionKey>& keys, const Shutter& shutter);
  // The pose the rule above gives at scene time t (between the steps the
  // renderer blends; exact at the steps).
  static Affine3f poseAt(const MotionKey& placement, const std::vector<MotionKey>& keys, float time);

  bool moving() const { return steps_.size() > 1; }
  int stepCount() const { return int(steps_.size()); }
  const Affine3f& step(int i) const { return steps_[size_t(i)]; }

  // Transform at normalised time u in [0, 1] (Embree ray time).
  Affine3f atNormalized(float u) const;
  // Bounds of an object-space box over the whole shutter. Exact for the
  // blended motion: a point's path is piecewise linear between the steps.
  Bounds3f sweptBounds(const Bounds3f& objectBounds) const;

  // The keyframe interpolation (translation and scale linear, rotation
  // slerp; end poses held outside the keys).
  static MotionKey interpolateKeys(const std::vector<MotionKey>& keys, float time);

 private:
  std::vector<Affine3f> steps_;
};

Bounds3f transformBounds(const Affine3f& m, const Bounds3f& b);

}  // namespace tdpm
