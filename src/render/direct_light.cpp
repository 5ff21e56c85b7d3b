// render/direct_light.cpp — shadow rays toward every light.
#include "render/direct_light.h"

#include <cmath>

#include "sampling/warp.h"

namespace tdpm {

template <class Stream>
Rgb directLight(const Scene& scene, const Hit& hit, const ShadingContext& ctx, float time01, Stream& sampler,
                int vertex, int bsdfSamples, const GuideCones* guide) {
  Rgb sum(0.0f);
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& light = scene.lights[i];
    if (bsdfSamples > 0 && bsdfAlone(light)) continue;  // the caller's BSDF rays carry it at full weight
    LightSample ls;
    Vec2f u = sampler.get2D(dims::vertexGroup(vertex, dims::kLightPosition, uint32_t(i)));
    if (!sampleLight(light, hit.p, time01, u, ls)) continue;
    Rgb f = bsdfEval(ctx, ls.wi);
    if (f.isBlack()) continue;
    float cosTheta = std::fabs(dot(ls.wi, ctx.frame.n));
    Vec3f o = scene.spawnOrigin(hit.p, hit.n, ls.wi);
    // Stop short of the light's own surface (area lights are geometry).
    float tMax = std::isinf(ls.distance) ? ls.distance : ls.distance * (1.0f - 1e-4f) - scene.epsilon(hit.p);
    if (tMax <= 0 || scene.occluded(o, ls.wi, tMax, time01)) continue;
    if (light.isDelta()) {
      sum += f * ls.li * cosTheta;
    } else {
      float w = 1.0f;
      if (bsdfSamples > 0) {
        float pb = bsdfPdf(ctx, ls.wi);
        if (guide) pb = guide->pdf(pb, ls.wi);
        w = 1.0f - emissionWeight(pb, ls.pdf, bsdfSamples);
      }
      sum += f * ls.li * (cosTheta * w / ls.pdf);
    }
  }
  return sum;
}

template Rgb directLight<RandomStream>(const Scene&, const Hit&, const ShadingContext&, float, RandomStream&, int, int,
                                      const GuideCones*);
template Rgb directLight<SobolStream>(const Scene&, const Hit&, const ShadingContext&, float, SobolStream&, int, int,
                                     const GuideCones*);

}  // namespace tdpm
