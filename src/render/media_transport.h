// render/media_transport.h — the media transport every integrator of
// scenes with participating media shares (issue 25): the transmittance of
// a shadow ray through media and interface surfaces, the per-sample
// random stream of the medium trackers, and the eye side's walk through
// interface surfaces to the next real surface, segment by segment.
// Used by the volumetric path tracer (render/volume_path.cpp), the photon
// integrator in media (render/photon_integrator_media.cpp) and the shadow
// rays of render/direct_light.cpp. Scenes without media never come here.
#pragma once
#include <cstdint>
#include <limits>

#include "core/rng.h"
#include "sampling/sampler.h"
#include "scene/scene.h"

namespace tdpm {

// Interface surfaces one path or shadow ray may cross: a bound against
// pathological geometry (a ray grazing along a mesh of interfaces), far
// above what any scene needs (a ray crosses each closed interface twice).
constexpr int kMaxMediumCrossings = 4096;

// The medium tracking's own random numbers (distances, event choices,
// ratio tracking): a PCG stream seeded from one 2D draw of the sample's
// stream, so that a sample stays a function of (seed, pixel, index).
// The group (vertex 0's reserved light-choice slot, sub 1) is one no
// other consumer draws.
template <class Stream>
Rng mediumRng(Stream& sampler) {
  Vec2f s = sampler.get2D(dims::vertexGroup(0, dims::kLightChoice, 1));
  uint64_t seed = (uint64_t(s.x * 16777216.0f) << 24) | uint64_t(s.y * 16777216.0f);
  return Rng(seed, 0x6d65646961ull);  // "media"
}

// The sky's (and a sun's) light seen from o along unit d through the medium
// m the ray escapes in: infinite lights shine from the media's world sphere
// inward (Scene::mediaExit, docs/media.md "Suns and skies"), so this is the
// transmittance up to where the ray leaves that sphere, and zero when the
// ray does not leave it outward ahead of o.
Rgb skyTransmittance(const Scene& s, const media::Medium& m, Vec3f o, Vec3f d, float time01, Rng& rng);

// Transmittance from o along unit d over [0, tMax] starting in `medium`:
// the product over the media crossed (closed form in homogeneous media,
// ratio tracking in grids: media/medium.h), through interface surfaces;
// zero at any other surface (and at an emitter's).
Rgb transmittanceTo(const Scene& s, Vec3f o, Vec3f d, float tMax, float time01, int32_t medium, Rng& rng);

// The eye side's ray through interfaces: from o along unit d in `medium`,
// calls segment(o_k, tEnd_k, medium_k) for every piece of the ray in a
// medium (medium_k >= 0; tEnd_k infinite when the ray escapes: the sky it
// then sees is attenuated up to the media's world, skyTransmittance), passing
// interface surfaces (the medium changes, nothing else), until the first
// real surface or emitter (true, `hit` filled, o and medium those of the
// last piece) or escape (false). `segment` returns false to stop the walk
// (its throughput went black): then the result is false with `stopped`.
template <class Segment>
bool intersectThroughInterfaces(const Scene& s, Vec3f& o, Vec3f d, float time01, int32_t& medium, Hit& hit,
                                bool& stopped, Segment&& segment) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  stopped = false;
  for (int crossing = 0; crossing < kMaxMediumCrossings; ++crossing) {
    bool found = s.intersect(o, d, kInf, time01, hit);
    if (medium >= 0 && !segment(o, found ? hit.t : kInf, medium)) {
      stopped = true;
      return false;
    }
    if (!found) return false;
    if (hit.isLight() || !s.objects[hit.object].isInterface) return true;
    medium = s.objects[hit.object].mediumAfter(hit.n, d, medium);
    o = s.spawnOrigin(hit.p, hit.n, d);
  }
  stopped = true;
  return false;
}

}  // namespace tdpm
