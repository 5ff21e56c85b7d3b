// render/path_tracer.h — unidirectional path tracing with next-event
// estimation (every light sampled at every non-delta vertex), multiple
// importance sampling against BSDF sampling for area lights (power
// heuristic), Russian roulette, and one time per path: the unbiased
// reference every photon-mapping method is judged against. Caustics from
// delta lights (point, spot, sun) through specular chains cannot be found
// by it: reference scenes for caustics use area lights.
#pragma once
#include "core/rng.h"
#include "sampling/sampler.h"
#include "scene/scene.h"

namespace tdpm {

class PathTracer {
 public:
  PathTracer(const Scene& scene, int maxDepth) : scene_(scene), maxDepth_(maxDepth) {}

  // Radiance arriving at `origin` from direction `dir`, at time time01.
  struct ThreadState {};
  // Stream: RandomStream or SobolStream (sampling/sampler.h); draws follow
  // its dimension order, vertex = depth.
  template <class Stream>
  Rgb radiance(Vec3f origin, Vec3f dir, float time01, Stream& sampler, ThreadState&) const {
    return trace(origin, dir, time01, sampler);
  }
  Rgb radiance(Vec3f origin, Vec3f dir, float time01, Rng& rng, ThreadState&) const { return radiance(origin, dir, time01, rng); }
  Rgb radiance(Vec3f origin, Vec3f dir, float time01, Rng& rng) const {
    RandomStream s{&rng};
    return trace(origin, dir, time01, s);
  }
  template <class Stream>
  Rgb trace(Vec3f origin, Vec3f dir, float time01, Stream& sampler) const;
  void flush(ThreadState&) const {}

 private:

  const Scene& scene_;
  int maxDepth_;
};

}  // namespace tdpm
