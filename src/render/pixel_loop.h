// render/pixel_loop.h — the one pixel loop inside a tile: for every pixel
// its sampler, its batch of sample indices, and for every sample the camera
// ray (render/camera_sample.h) and the path's stream. What the samples are
// added into is the caller's, so the three passes are what they accumulate,
// not copies of the loop: the fixed-budget and adaptive pass (mean,
// variance, half-buffer error: render/renderer.cpp), the progressive pass
// (the pass mean with its eye/rest split: render/progressive.cpp) and the
// eye-only pilot (luminance statistics: render/sample_allocation.cpp).
// Everything is inlined into the caller's tile task: no allocation and no
// virtual call per sample.
#pragma once
#include <cstddef>
#include <cstdint>

#include "render/camera_sample.h"
#include "render/tile_loop.h"
#include "scene/camera.h"

namespace tdpm {

// For each pixel of `tile` (row-major image of `width` pixels):
//   batch(idx, first, count) -> false: the pixel takes no samples now;
//     else it takes sample indices [first, first + count) of its sequence;
//   sample(idx, i, ray, stream) for each, in index order;
//   done(idx) after the last.
template <class PixelSampler, class Batch, class Sample, class Done>
inline void samplePixels(const Tile& tile, int width, const Camera& camera, const CameraSamplePlan& plan,
                         uint64_t seed, Batch&& batch, Sample&& sample, Done&& done) {
  for (int y = tile.y0; y < tile.y1; ++y)
    for (int x = tile.x0; x < tile.x1; ++x) {
      const size_t idx = size_t(y) * size_t(width) + size_t(x);
      uint32_t first = 0, count = 0;
      if (!batch(idx, first, count)) continue;
      PixelSampler ps(seed, idx);
      ps.startBatch(first, int(count));
      for (uint32_t i = first; i < first + count; ++i) {
        const CameraRay ray = cameraRay(camera, plan, ps, x, y, i);
        typename PixelSampler::Stream stream = ps.stream(i);
        sample(idx, i, ray, stream);
      }
      done(idx);
    }
}

}  // namespace tdpm
