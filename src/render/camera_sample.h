// render/camera_sample.h — the one camera sample: (pixel, sample index,
// sampling plan) -> the camera ray, its time and where in the pixel it
// landed, through the lens (pbrt-v4's GetCameraSample + GenerateRay, Mitsuba's render_sample).
// Every pixel loop takes its rays from cameraRay(): the fixed-budget and
// adaptive passes (render/renderer.cpp), the progressive pass
// (render/progressive.cpp) and the eye-only pilot (render/sample_allocation.cpp),
// so the time remap (a still scene, an accumulation frame's instant, an
// animation frame's part of the timeline) is written once, here.
//
// A thin-lens camera (scene/camera.h) takes its lens point from the
// sampler's lens dimensions (lensSample: drawn only when the camera has a
// lens, so a pinhole render draws what it always drew). The pixel filter is importance sampled (sampling/filter.h), so every sample's
// filter weight is 1 and nothing is multiplied.
#pragma once
#include <cmath>
#include <cstdint>

#include "math/vec.h"
#include "motion/shutter.h"
#include "sampling/filter.h"
#include "sampling/stratified.h"
#include "scene/camera.h"

namespace tdpm {

// When in the (normalised) shutter a camera sample is taken.
struct SampleTimes {
  float fixed01 = -1.0f;  // >= 0: every sample at this time (an accumulation frame or pass instant)
  bool moving = true;     // false: a scene without motion, every sample at time 0
  // The part of the shutter sampled: an animation frame's part of the
  // timeline; [0, 1] is the whole shutter (lo + u (hi - lo) is then u, bit for bit).
  float lo01 = 0.0f, hi01 = 1.0f;

  // The sampler's time u in [0,1) -> the sample's time.
  float remap(float u) const {
    if (fixed01 >= 0) return fixed01;
    if (!moving) return 0.0f;
    return lo01 + u * (hi01 - lo01);
  }
};

// An animation frame's part of the timeline [open, close] (scene seconds)
// into `t`; a NaN open leaves the whole shutter. The fixed-budget frame
// (renderFrame) and the progressive frame's passes both map it here.
inline void setFrameTimes(SampleTimes& t, const Shutter& sceneShutter, float open, float close) {
  if (!std::isfinite(open)) return;
  t.lo01 = sceneShutter.normalized(open);
  t.hi01 = sceneShutter.normalized(close);
}

// What every camera sample of a render shares.
struct CameraSamplePlan {
  PixelFilter filter;  // where in (and around) the pixel a sample lands
  SampleTimes times;
};

struct CameraRay {
  Vec3f origin, direction;
  float time01 = 0.0f;  // normalised shutter time; every ray of the eye path uses it
};

// Sample `index` of pixel (x, y) from its per-pixel sampler (sampling/sampler.h;
// a batch containing `index` started). Reads the sampler's camera
// dimensions only: the caller takes ps.stream(index) for the path after it.
template <class PixelSampler>
inline CameraRay cameraRay(const Camera& camera, const CameraSamplePlan& plan, const PixelSampler& ps, int x, int y,
                           uint32_t index) {
  const CameraSample cs = ps.camera(index);
  CameraRay r;
  r.time01 = plan.times.remap(cs.time01);
  const Vec2f p = plan.filter.sample(cs.pixelOffset);
  camera.generateRay({float(x) + p.x, float(y) + p.y}, r.time01, lensSample(camera, ps, index), r.origin, r.direction);
  return r;
}

}  // namespace tdpm
