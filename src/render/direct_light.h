// render/direct_light.h — next-event estimation shared by the integrators:
// one shadow ray per light at the path's time. Area lights are combined
// with `bsdfSamples` BSDF-sampled rays by Veach's multi-sample power
// heuristic, w = p_l^2 / (p_l^2 + (n p_b)^2); the caller adds those rays'
// emission with emissionWeight(). bsdfSamples = 0: light sampling alone,
// at full weight (the caller then ignores emission its rays hit).
#pragma once
#include "core/rng.h"
#include "sampling/sampler.h"
#include "scene/bsdf.h"
#include "render/guided_sampling.h"
#include "scene/scene.h"

namespace tdpm {

// `vertex` is the path vertex (sampling/sampler.h dimension order): light
// i's point is drawn from group vertexGroup(vertex, kLightPosition, i).
// Defined for RandomStream and SobolStream. `guide`: when the caller's
// BSDF rays come from the guided mixture (render/guided_sampling.h), its
// density replaces the BSDF's in the MIS weight.
template <class Stream>
Rgb directLight(const Scene& scene, const Hit& hit, const ShadingContext& ctx, float time01, Stream& sampler,
                int vertex, int bsdfSamples, const GuideCones* guide = nullptr);
// Scenes with media: the same, each shadow ray weighted by its
// transmittance through media and interface surfaces
// (render/media_transport.h), starting in the medium on the side of the
// hit it leaves into (`medium`: the path's medium at the hit, kept where
// the object bounds no media); rng: the sample's medium stream.
template <class Stream>
Rgb directLightMedia(const Scene& scene, const Hit& hit, const ShadingContext& ctx, float time01, Stream& sampler,
                     int vertex, int bsdfSamples, const GuideCones* guide, int32_t medium, Rng& rng);

// MIS weight of a BSDF-sampled ray (one of `bsdfSamples`, density
// bsdfPdf) that hit an area light which light sampling would have chosen
// with density lightPdf.
inline float emissionWeight(float bsdfPdf, float lightPdf, int bsdfSamples) {
  float b = float(bsdfSamples) * bsdfPdf;
  return b * b / (b * b + lightPdf * lightPdf);
}

// A constant environment is left to BSDF sampling when there is any (as
// pbrt-v4 does: its uniform sphere samples are no better than cosine-weighted
// BSDF rays, and on caustic-glass at 32 spp they cost 12% more time for 6%
// more relMSE); directLight samples it only with bsdfSamples = 0.
inline bool bsdfAlone(const Light& light) {
  return light.type == Light::Type::Environment && light.env->isConstant();
}

// What a ray escaping along `dir` finds of the environment lights: each
// one's radiance, weighted against its own light sampling by the same
// heuristic (fullWeight: a camera or delta-sampled ray, which light
// sampling could not have made). Zero without environment lights.
// bsdfSamples >= 1 (the escaping ray is one of them).
// A BSDF-sampled ray (or a camera ray) that hits an area light: its
// radiance le and the MIS weight w against the light sample taken at lastP
// (1 after a delta bounce or from the camera, lastDelta), as both path
// tracers add it (render/path_tracer.cpp, render/volume_path.cpp); false
// when le is black. The caller adds beta * le * w itself, so that the
// product rounds as it always has (bench/bitmatch).
inline bool areaEmissionOnHit(const Scene& scene, const Hit& hit, Vec3f dir, float time01, Vec3f lastP, float lastPdf,
                              bool lastDelta, Rgb& le, float& w) {
  const Light& light = scene.lights[size_t(hit.light)];
  AreaLightFrame f = areaLightFrame(light, time01);
  le = areaLightRadiance(light, f, hit.n, -dir);
  if (le.isBlack()) return false;
  w = lastDelta ? 1.0f : emissionWeight(lastPdf, areaLightPdf(light, f, lastP, hit.p, hit.n), 1);
  return true;
}

inline Rgb environmentEmission(const Scene& scene, Vec3f dir, float bsdfPdf, int bsdfSamples, bool fullWeight) {
  Rgb sum(0.0f);
  for (uint32_t i : scene.environmentLights) {
    const Light& light = scene.lights[i];
    Rgb le = environmentRadiance(light, dir);
    if (le.isBlack()) continue;
    bool full = fullWeight || bsdfAlone(light);
    sum += le * (full ? 1.0f : emissionWeight(bsdfPdf, environmentPdf(light, dir), bsdfSamples));
  }
  return sum;
}

}  // namespace tdpm
