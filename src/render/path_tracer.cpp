// render/path_tracer.cpp — the reference integrator.
#include "render/path_tracer.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sampling/warp.h"
#include "render/direct_light.h"
#include "scene/bsdf.h"

namespace tdpm {

namespace {
constexpr int kRouletteStartDepth = 3;
}

Rgb PathTracer::radiance(Vec3f origin, Vec3f dir, float time01, Rng& rng) const {
  Rgb L(0.0f), beta(1.0f);
  bool lastDelta = true;  // the camera ray counts as "specular": no MIS on a direct hit
  float lastPdf = 0.0f;
  Vec3f lastP = origin;
  for (int depth = 0; depth < maxDepth_; ++depth) {
    Hit hit;
    if (!scene_.intersect(origin, dir, std::numeric_limits<float>::infinity(), time01, hit)) {
      L += beta * scene_.background;
      break;
    }
    // ---- emission: a BSDF-sampled ray that hits an area light ----
    if (hit.isLight()) {
      const Light& light = scene_.lights[size_t(hit.light)];
      AreaLightFrame f = areaLightFrame(light, time01);
      Rgb le = areaLightRadiance(light, f, -dir);
      if (!le.isBlack()) {
        float w = lastDelta ? 1.0f : emissionWeight(lastPdf, areaLightPdf(light, f, lastP, hit.p), 1);
        L += beta * le * w;
      }
      break;  // emitters do not reflect
    }
    const Material& mat = scene_.materials[scene_.objects[hit.object].material];
    ShadingContext ctx = makeShadingContext(mat, mat.albedo.at(hit.localP), hit.n, -dir);

    // ---- next-event estimation ----
    if (!mat.isDeltaOnly()) L += beta * directLight(scene_, hit, ctx, time01, rng, /*bsdfSamples=*/1);

    // ---- continue the path ----
    BsdfSample bs;
    Vec2f u{rng.uniform(), rng.uniform()};
    if (!bsdfSample(ctx, u, rng.uniform(), Transport::Radiance, bs)) break;
    beta *= bs.weight;
    if (beta.isBlack() || !isFinite(beta)) break;
    lastDelta = bs.delta;
    lastPdf = bs.pdf;
    lastP = hit.p;
    origin = scene_.spawnOrigin(hit.p, hit.n, bs.wi);
    dir = bs.wi;

    if (depth + 1 >= kRouletteStartDepth) {
      float survive = std::min(0.95f, beta.maxComponent());
      if (rng.uniform() >= survive) break;
      beta = beta / survive;
    }
  }
  return L;
}

}  // namespace tdpm
