// render/volume_path.cpp — volumetric path tracing (issue 25), the `pathtrace`
// integrator of scenes with participating media (PathTracer::trace hands
// over here when Scene::hasMedia()). As pbrt-v4's volpath:
//   - a ray carries its medium (the camera's at the start); at a surface
//     with a medium interface the next medium is the one on the side the
//     new direction points into; "interface" surfaces are skipped (the ray
//     goes on, changing medium only; no path vertex);
//   - free flight (media/medium.h: closed form / delta tracking, spectral
//     tracking weights for RGB) decides whether the segment to the next
//     surface scatters, is absorbed or passes;
//   - at a medium vertex: next-event estimation with the Henyey-Greenstein
//     phase function, then a phase-sampled direction (weight 1);
//   - at a surface vertex: next-event estimation with the BSDF and a BSDF
//     sample, as render/path_tracer.cpp;
//   - every shadow ray multiplies the transmittance of each medium it
//     crosses (closed form / ratio tracking) through interface surfaces and
//     stops at any other surface (render/media_transport.h);
//   - MIS (power heuristic) between light sampling and phase / BSDF
//     sampling for area and environment lights, with directional densities
//     only: both strategies see the same transmittance (in expectation), so
//     weights that sum to one per direction keep the sum unbiased.
// Differs from pbrt-v4: pbrt folds the free-flight and ratio-tracking
// densities into its MIS weights (r_u, r_l) and uses the hero wavelength's
// majorant; here spectral tracking keeps the weights per channel and MIS
// directional (docs/media.md). The caustic guide serves the first two
// diffuse surface vertices as in path_tracer.cpp (its photons are traced
// through the media, render/caustic_guide.h): the BSDF ray from the guided
// mixture, its density in every MIS weight and undone for roulette.
#include <algorithm>
#include <cmath>
#include <limits>

#include "media/medium.h"
#include "media/phase.h"
#include "render/caustic_guide.h"
#include "render/direct_light.h"
#include "render/guided_sampling.h"
#include "render/media_transport.h"
#include "render/path_tracer.h"
#include "scene/bsdf.h"

namespace tdpm {

namespace {

constexpr int kRouletteStartDepth = 3;  // as render/path_tracer.cpp
constexpr int kMaxCrossings = kMaxMediumCrossings;  // render/media_transport.h
constexpr float kInf = std::numeric_limits<float>::infinity();

// What scatters at a path vertex: a phase function (surface == null) or
// a surface's BSDF, sampled by the guide's mixture where `guide` is active.
// f includes the BSDF's |cos|.
struct Scatterer {
  const ShadingContext* surface = nullptr;
  Vec3f wo;
  float g = 0.0f;
  const GuideCones* guide = nullptr;
  Rgb f(Vec3f wi) const {
    if (!surface) return Rgb(media::henyeyGreenstein(dot(wo, wi), g));
    return bsdfEval(*surface, wi) * std::fabs(dot(wi, surface->frame.n));
  }
  float pdf(Vec3f wi) const {
    if (!surface) return media::henyeyGreenstein(dot(wo, wi), g);
    float pb = bsdfPdf(*surface, wi);
    return guide ? guide->pdf(pb, wi) : pb;
  }
};

// Next-event estimation at point p (a medium point, or a surface hit with
// its object), every light once, MIS against one phase / BSDF sample.
template <class Stream>
Rgb nextEvent(const Scene& s, Vec3f p, const Hit* hit, const Scatterer& sc, int32_t medium, float time01,
              Stream& sampler, int vertex, Rng& rng) {
  Rgb sum(0.0f);
  for (size_t i = 0; i < s.lights.size(); ++i) {
    const Light& light = s.lights[i];
    if (bsdfAlone(light)) continue;  // phase / BSDF rays carry it at full weight
    LightSample ls;
    Vec2f u = sampler.get2D(dims::vertexGroup(vertex, dims::kLightPosition, uint32_t(i)));
    if (!sampleLight(light, p, time01, u, ls)) continue;
    Rgb f = sc.f(ls.wi);
    if (f.isBlack()) continue;
    Vec3f o = p;
    int32_t m = medium;
    if (hit) {
      o = s.spawnOrigin(hit->p, hit->n, ls.wi);
      m = s.objects[hit->object].mediumAfter(hit->n, ls.wi, medium);
    }
    float tMax = std::isinf(ls.distance) ? ls.distance : ls.distance * (1.0f - 1e-4f) - s.epsilon(p);
    if (tMax <= 0) continue;
    Rgb T = transmittanceTo(s, o, ls.wi, tMax, time01, m, rng);
    if (T.isBlack()) continue;
    if (light.isDelta()) {
      sum += f * T * ls.li;
    } else {
      float w = 1.0f - emissionWeight(sc.pdf(ls.wi), ls.pdf, 1);
      sum += f * T * ls.li * (w / ls.pdf);
    }
  }
  return sum;
}

// Russian roulette as render/path_tracer.cpp: only below weight 1, from
// kRouletteStartDepth. False: the path ends.
template <class Stream>
bool survives(Rgb& beta, float etaScale, float guideScale, int depth, Stream& sampler) {
  float rr = beta.maxComponent() * etaScale * guideScale;
  if (depth + 1 < kRouletteStartDepth || rr >= 1.0f) return true;
  if (sampler.get1D(dims::vertexGroup(depth, dims::kRoulette)) >= rr) return false;
  beta = beta / rr;
  return true;
}

}  // namespace

// Longer than 80 lines on purpose, as PathTracer::trace: one sample's path,
// its throughput, MIS state and medium kept local to the loop.
template <class Stream>
Rgb PathTracer::traceMedia(Vec3f origin, Vec3f dir, float time01, Stream& sampler, ThreadState& ts) const {
  Rgb L(0.0f), beta(1.0f);
  float etaScale = 1.0f;   // as trace(): refraction's 1/eta^2 undone for roulette
  float guideScale = 1.0f; // as trace(): the guide's p_mix / p_bsdf undone for roulette
  int diffuseVertices = 0; // non-delta surface vertices so far (the guide serves the first two)
  GuideCones& cones = ts.cones;
  bool beyondWorld = false;  // the ray starts where it left the media's world: no sky ahead
  bool lastDelta = true;   // camera ray: full weight on emission
  float lastPdf = 0.0f;
  Vec3f lastP = origin;
  int32_t medium = scene_.cameraMedium;
  Rng rng = mediumRng(sampler);
  int lastDepth = maxDepth_;
  int depth = 0;
  for (int crossings = 0; crossings < kMaxCrossings;) {
    Hit hit;
    bool found = scene_.intersect(origin, dir, kInf, time01, hit);
    // An escaping ray in a medium meets the sky where it leaves the media's
    // world (suns and skies shine from that sphere inward, docs/media.md),
    // and the medium goes on beyond it without sky.
    float tFlight = found ? hit.t : kInf;
    bool skyAhead = !found;
    if (medium >= 0 && !found) {
      const float exit = beyondWorld ? 0.0f : scene_.mediaExit(origin, dir);
      skyAhead = exit > 0.0f;
      if (skyAhead) tFlight = exit;
    }
    beyondWorld = false;
    if (medium >= 0) {
      const media::Medium& med = scene_.media[size_t(medium)];
      media::FreeFlight ff = media::sampleFreeFlight(med, origin, dir, tFlight, time01, rng, beta);
      if (ff.event == media::FreeFlight::Event::Absorb || beta.isBlack() || !isFinite(beta)) break;
      if (ff.event == media::FreeFlight::Event::Scatter) {
        // ---- a medium vertex ----
        if (depth == lastDepth) break;
        Vec3f p = origin + dir * ff.t;
        Scatterer sc{nullptr, -dir, med.g};
        L += beta * nextEvent(scene_, p, nullptr, sc, medium, time01, sampler, depth, rng);
        Vec2f u = sampler.get2D(dims::vertexGroup(depth, dims::kBsdf));
        Vec3f wi;
        lastPdf = media::sampleHenyeyGreenstein(-dir, med.g, u.x, u.y, wi);  // weight f / pdf = 1
        lastDelta = false;
        lastP = p;
        origin = p;
        dir = wi;
        if (directOnly_) lastDepth = std::min(lastDepth, depth + 1);
        if (!survives(beta, etaScale, guideScale, depth, sampler)) break;
        ++depth;
        continue;
      }
    }
    if (!found) {
      if (skyAhead) {
        L += beta * scene_.background;
        if (!scene_.environmentLights.empty()) L += beta * environmentEmission(scene_, dir, lastPdf, 1, lastDelta);
      }
      if (medium < 0 || std::isinf(tFlight)) break;
      origin = origin + dir * tFlight;  // on into the medium beyond the sphere
      beyondWorld = true;
      ++crossings;
      continue;
    }
    if (hit.isLight()) {  // ---- emission, attenuated by beta's media ----
      Rgb le;
      float w;
      if (areaEmissionOnHit(scene_, hit, dir, time01, lastP, lastPdf, lastDelta, le, w)) L += beta * le * w;
      break;
    }
    const SceneObject& obj = scene_.objects[hit.object];
    if (obj.isInterface) {  // no surface: only the medium changes
      medium = obj.mediumAfter(hit.n, dir, medium);
      origin = scene_.spawnOrigin(hit.p, hit.n, dir);
      ++crossings;
      continue;
    }
    // ---- a surface vertex ----
    if (depth == lastDepth) break;
    Rgb mixWeight(1.0f);  // a per-channel mix's weight (Scene::materialAt)
    const Material& mat = scene_.materialAt(hit, -dir, &mixWeight);
    std::optional<Material> textured;
    ShadingContext ctx = scene_.shadingContext(mat, hit, -dir, textured, mixWeight);
    if (directOnly_ && !mat.isDeltaOnly()) lastDepth = std::min(lastDepth, depth + 1);
    cones.clear();
    if (guide_ && !mat.isDeltaOnly() && diffuseVertices < kGuidedDiffuseVertices)
      guide_->conesAt(mat, hit.p, ctx.frame.n, cones);
    if (!mat.isDeltaOnly()) {
      ++diffuseVertices;
      Scatterer sc{&ctx, -dir, 0.0f, &cones};
      L += beta * nextEvent(scene_, hit.p, &hit, sc, medium, time01, sampler, depth, rng);
    }
    BsdfSample bs;
    Vec3f ub = sampler.get3D(dims::vertexGroup(depth, dims::kBsdf));
    if (!guidedBsdfSample(ctx, cones, {ub.x, ub.y}, ub.z, bs)) break;
    if (cones.active()) {
      float pb = bsdfPdf(ctx, bs.wi);
      if (pb > 0.0f) guideScale *= bs.pdf / pb;
    }
    beta *= bs.weight;
    if (beta.isBlack() || !isFinite(beta)) break;
    if (mat.transmits() && (dot(bs.wi, hit.n) < 0) != (dot(-dir, hit.n) < 0)) {
      float eta = dot(-dir, hit.n) > 0 ? mat.ior : 1.0f / mat.ior;
      etaScale *= eta * eta;
    }
    medium = obj.mediumAfter(hit.n, bs.wi, medium);
    lastDelta = bs.delta;
    lastPdf = bs.pdf;
    lastP = hit.p;
    origin = scene_.spawnOrigin(hit.p, hit.n, bs.wi);
    dir = bs.wi;
    if (!survives(beta, etaScale, guideScale, depth, sampler)) break;
    ++depth;
  }
  return L;
}

template Rgb PathTracer::traceMedia<RandomStream>(Vec3f, Vec3f, float, RandomStream&, ThreadState&) const;
template Rgb PathTracer::traceMedia<SobolStream>(Vec3f, Vec3f, float, SobolStream&, ThreadState&) const;

}  // namespace tdpm
