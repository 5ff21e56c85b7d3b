// render/path_tracer.cpp — the reference integrator.
#include "render/path_tracer.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sampling/warp.h"
#include "render/direct_light.h"
#include "render/guided_sampling.h"
#include "scene/bsdf.h"

namespace tdpm {

namespace {
constexpr int kRouletteStartDepth = 3;
}

// Longer than 80 lines on purpose: it is one sample's path, the render's
// inner loop; its throughput, MIS state and running sum stay local to it
// instead of passing through a call per vertex.
template <class Stream>
Rgb PathTracer::trace(Vec3f origin, Vec3f dir, float time01, Stream& sampler, ThreadState& ts) const {
  if (scene_.hasMedia()) return traceMedia(origin, dir, time01, sampler, ts);
  Rgb L(0.0f), beta(1.0f);
  // Product of eta^2 over the refractions so far: the radiance scaling
  // 1/eta^2 a refraction puts into beta is undone for Russian roulette,
  // which should judge the path's energy, not its being inside glass
  // (inside the ball beta is 1/2.25 of what it will be again outside).
  float etaScale = 1.0f;
  // Roulette also undoes the guide: a guided direction's weight f cos / p
  // is small because p is large (the guide is sure of it), not because the
  // path carries little, and judging by it killed ~99.98% of guided paths
  // on their way through the glass (their survivors came back as
  // fireflies). guideScale = p_mix / p_bsdf over the guided vertices, so
  // roulette sees the weight plain BSDF sampling would have given.
  float guideScale = 1.0f;
  bool lastDelta = true;  // the camera ray counts as "specular": no MIS on a direct hit
  float lastPdf = 0.0f;
  int diffuseVertices = 0;  // non-delta vertices so far
  Vec3f lastP = origin;
  // maxDepth_ vertices scatter (next-event estimation and a BSDF sample);
  // the ray leaving the last one is still traced, for the emission and sky
  // it finds: it is the BSDF half of that vertex's MIS pair, without which
  // direct light from area lights would lose its BSDF-sampled share (all of
  // it for max_depth 1). pbrt's maxdepth counts the same way.
  // directOnly_: the first non-delta vertex is the last to scatter.
  int lastDepth = maxDepth_;
  GuideCones& cones = ts.cones;  // this vertex's guide, cleared per vertex
  for (int depth = 0;; ++depth) {
    Hit hit;
    if (!scene_.intersect(origin, dir, std::numeric_limits<float>::infinity(), time01, hit)) {
      L += beta * scene_.background;
      if (!scene_.environmentLights.empty()) L += beta * environmentEmission(scene_, dir, lastPdf, 1, lastDelta);
      break;
    }
    // ---- emission: a BSDF-sampled ray that hits an area light ----
    if (hit.isLight()) {
      Rgb le;
      float w;
      if (areaEmissionOnHit(scene_, hit, dir, time01, lastP, lastPdf, lastDelta, le, w)) L += beta * le * w;
      break;  // emitters do not reflect
    }
    if (depth == lastDepth) break;
    Rgb mixWeight(1.0f);  // a per-channel mix's weight (Scene::materialAt)
    const Material& mat = scene_.materialAt(hit, -dir, &mixWeight);
    std::optional<Material> textured;
    ShadingContext ctx = scene_.shadingContext(mat, hit, -dir, textured, mixWeight);

    // Guide cones at the first two diffuse vertices: not only a caustic
    // seen directly (or in a mirror), but also one lighting what is seen,
    // e.g. the wall or the box's shadow lit by the bright caustic on the box
    // top (wall -> box top -> glass -> lamp). With the first vertex guided
    // only, such paths made 27% and 11% of cube-caustic's relMSE at 1024
    // spp (seeds 1 and 2). The guide's occupancy grid answers for most
    // vertices, away from every caustic, without a k-NN.
    cones.clear();
    if (guide_ && !mat.isDeltaOnly() && diffuseVertices < kGuidedDiffuseVertices)
      guide_->conesAt(mat, hit.p, ctx.frame.n, cones);
    if (!mat.isDeltaOnly()) ++diffuseVertices;
    if (directOnly_ && !mat.isDeltaOnly()) lastDepth = std::min(lastDepth, depth + 1);

    // ---- next-event estimation ----
    if (!mat.isDeltaOnly())
      L += beta * directLight(scene_, hit, ctx, time01, sampler, depth, /*bsdfSamples=*/1, &cones);

    // ---- continue the path ----
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
      float eta = dot(-dir, hit.n) > 0 ? mat.ior : 1.0f / mat.ior;  // eta_t / eta_i
      etaScale *= eta * eta;
    }
    lastDelta = bs.delta;
    lastPdf = bs.pdf;
    lastP = hit.p;
    origin = scene_.spawnOrigin(hit.p, hit.n, bs.wi);
    dir = bs.wi;

    // Roulette only a path whose weight has fallen below 1 (a path at full
    // weight gains nothing from being killed 5% of the time).
    float rr = beta.maxComponent() * etaScale * guideScale;
    if (depth + 1 >= kRouletteStartDepth && rr < 1.0f) {
      float survive = rr;
      if (sampler.get1D(dims::vertexGroup(depth, dims::kRoulette)) >= survive) break;
      beta = beta / survive;
    }
  }
  return L;
}

template Rgb PathTracer::trace<RandomStream>(Vec3f, Vec3f, float, RandomStream&, ThreadState&) const;
template Rgb PathTracer::trace<SobolStream>(Vec3f, Vec3f, float, SobolStream&, ThreadState&) const;

}  // namespace tdpm
