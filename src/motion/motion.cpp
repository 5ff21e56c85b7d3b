// motion/motion.cpp — resampling keyframes into Embree-style time steps.
#include "motion/motion.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace tdpm {

Motion Motion::still(const Affine3f& placement) {
  Motion m;
  m.steps_ = {placement};
  return m;
}

MotionKey Motion::interpolateKeys(const std::vector<MotionKey>& keys, float time) {
  TDPM_ASSERT(!keys.empty(), "no keyframes");
  if (time <= keys.front().time) return keys.front();
  if (time >= keys.back().time) return keys.back();
  size_t i = 1;
  while (keys[i].time < time) ++i;
  const MotionKey& a = keys[i - 1];
  const MotionKey& b = keys[i];
  float s = (time - a.time) / (b.time - a.time);
  return {time, lerp(a.translate, b.translate, s), slerp(a.rotate, b.rotate, s), lerp(a.scale, b.scale, s)};
}

Affine3f Motion::poseAt(const MotionKey& p, const std::vector<MotionKey>& keys, float time) {
  MotionKey k = interpolateKeys(keys, time);
  return Affine3f::fromTRS(p.translate + k.translate, k.rotate * p.rotate, k.scale * p.scale);
}

namespace {

// Smallest interval count n in [minN, 128] with every keyframe time on the
// grid; 128 if none fits (the keyframes are then only approximately hit).
int alignedIntervalCount(const std::vector<float>& u, int minN) {
  for (int n = std::max(1, minN); n < Motion::kMaxSteps; ++n) {
    bool aligned = true;
    for (float x : u) {
      float g = x * float(n);
      if (std::fabs(g - std::round(g)) > 1e-4f) { aligned = false; break; }
    }
    if (aligned) return n;
  }
  return Motion::kMaxSteps - 1;
}

}  // namespace

Motion Motion::keyframed(const MotionKey& placement, const std::vector<MotionKey>& keys, const Shutter& shutter) {
  TDPM_ASSERT(keys.size() >= 2, "keyframed motion needs two keys");
  if (shutter.instant()) return still(poseAt(placement, keys, shutter.open));

  std::vector<float> u;
  u.reserve(keys.size());
  for (const MotionKey& k : keys) u.push_back(shutter.normalized(k.time));

  // Enough intervals that no step rotates more than kMaxStepRotation.
  int minN = 1;
  for (size_t i = 1; i < keys.size(); ++i) {
    float angle = keys[i - 1].rotate.angleTo(keys[i].rotate);
    float du = u[i] - u[i - 1];
    if (angle > 0 && du > 0) minN = std::max(minN, int(std::ceil(angle / (kMaxStepRotation * du))));
  }
  // Keyframes at the shutter ends only, no rotation, linear: 2 steps suffice.
  int n = alignedIntervalCount(u, std::min(minN, kMaxSteps - 1));

  Motion m;
  m.steps_.resize(size_t(n) + 1);
  for (int i = 0; i <= n; ++i) {
    float t = shutter.fromNormalized(float(i) / float(n));
    m.steps_[size_t(i)] = poseAt(placement, keys, t);
  }
  return m;
}

Affine3f Motion::atNormalized(float u) const {
  if (steps_.size() == 1) return steps_[0];
  float s = std::clamp(u, 0.0f, 1.0f) * float(steps_.size() - 1);
  // Same segment choice as Embree: floor, clamped to the last segment.
  int i = std::min(int(s), int(steps_.size()) - 2);
  return lerp(steps_[size_t(i)], steps_[size_t(i) + 1], s - float(i));
}

Bounds3f transformBounds(const Affine3f& m, const Bounds3f& b) {
  Bounds3f r;
  for (int c = 0; c < 8; ++c)
    r.extend(m.point({(c & 1) ? b.hi.x : b.lo.x, (c & 2) ? b.hi.y : b.lo.y, (c & 4) ? b.hi.z : b.lo.z}));
  return r;
}

Bounds3f Motion::sweptBounds(const Bounds3f& objectBounds) const {
  Bounds3f r;
  for (const Affine3f& s : steps_) r.extend(transformBounds(s, objectBounds));
  return r;
}

}  // namespace tdpm
