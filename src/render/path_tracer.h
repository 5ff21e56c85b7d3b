// render/path_tracer.h — unidirectional path tracing with next-event
// estimation (every light sampled at every non-delta vertex), multiple
// importance sampling against BSDF sampling for area lights (power
// heuristic), Russian roulette, and one time per path: the unbiased
// reference every photon-mapping method is judged against. Caustics from
// delta lights (point, spot, sun) through specular chains cannot be found
// by it: reference scenes for caustics use area lights. Caustics from area
// lights are found far more often when the first two diffuse vertices aim
// part of their samples where caustic photons came from
// (render/caustic_guide.h).
#pragma once
#include "core/rng.h"
#include "photon/kdtree.h"
#include "render/caustic_guide.h"
#include "sampling/sampler.h"
#include "scene/scene.h"

namespace tdpm {

class PathTracer {
 public:
  // guide: null or disabled for plain BSDF sampling; must outlive the tracer.
  // directOnly: RenderOptions::directOnly (pbrt's directlighting).
  PathTracer(const Scene& scene, int maxDepth, const CausticGuide* guide = nullptr, bool directOnly = false)
      : scene_(scene), maxDepth_(maxDepth), guide_(guide && guide->enabled() ? guide : nullptr), directOnly_(directOnly) {}

  // Per-thread scratch: none at present (the guide's k-NN keeps its few
  // candidates on the stack); kept so that callers need not change.
  // Per-thread scratch: the guide cones of the vertex being shaded (32
  // cones; built once per thread, not per path: their construction was
  // 1% of a path-traced Cornell box).
  struct ThreadState {
    GuideCones cones;
  };
  // Radiance arriving at `origin` from direction `dir`, at time time01.
  // Stream: RandomStream or SobolStream (sampling/sampler.h); draws follow
  // its dimension order, vertex = depth.
  template <class Stream>
  Rgb radiance(Vec3f origin, Vec3f dir, float time01, Stream& sampler, ThreadState& ts) const {
    return trace(origin, dir, time01, sampler, ts);
  }
  Rgb radiance(Vec3f origin, Vec3f dir, float time01, Rng& rng, ThreadState& ts) const {
    RandomStream s{&rng};
    return trace(origin, dir, time01, s, ts);
  }
  Rgb radiance(Vec3f origin, Vec3f dir, float time01, Rng& rng) const {
    ThreadState ts;
    return radiance(origin, dir, time01, rng, ts);
  }
  template <class Stream>
  Rgb trace(Vec3f origin, Vec3f dir, float time01, Stream& sampler, ThreadState& ts) const;
  void flush(ThreadState&) const {}

 private:
  // Scenes with participating media (render/volume_path.cpp): free flight,
  // phase-function vertices, transmittance in next-event estimation and
  // medium tracking through interfaces. trace() hands over at its start.
  template <class Stream>
  Rgb traceMedia(Vec3f origin, Vec3f dir, float time01, Stream& sampler, ThreadState& ts) const;

  // Diffuse (non-delta) surface vertices of an eye path that the caustic
  // guide serves: the first (a caustic seen) and the second (a caustic
  // lighting what is seen). On cube-caustic at 1024 spp (seeds 1, 2;
  // docs/sampling.md) relMSE was 0.35 guiding the first only, 0.24 the first
  // two, 0.23 all, and every guided vertex near photons costs a k-NN (~2,100
  // instructions in the 196k-photon guide of a 1024-spp render).
  static constexpr int kGuidedDiffuseVertices = 2;

  const Scene& scene_;
  int maxDepth_;
  const CausticGuide* guide_;
  bool directOnly_;
};

}  // namespace tdpm
