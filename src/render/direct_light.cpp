// render/direct_light.cpp — shadow rays toward every light (through media
// in scenes with media: render/media_transport.h).
#include "render/direct_light.h"

#include <cmath>

#include "render/media_transport.h"
#include "sampling/warp.h"

namespace tdpm {

namespace {

// kMedia: each shadow ray carries its transmittance through media and
// interfaces instead of the binary visibility (a separate instantiation,
// so that scenes without media run the loop they always ran).
template <bool kMedia, class Stream>
Rgb directLightImpl(const Scene& scene, const Hit& hit, const ShadingContext& ctx, float time01, Stream& sampler,
                    int vertex, int bsdfSamples, const GuideCones* guide, int32_t medium, Rng* rng) {
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
    Rgb T(1.0f);
    if constexpr (kMedia) {
      if (tMax <= 0) continue;
      T = transmittanceTo(scene, o, ls.wi, tMax, time01, scene.objects[hit.object].mediumAfter(hit.n, ls.wi, medium),
                          *rng);
      if (T.isBlack()) continue;
      f = f * T;
    } else {
      if (tMax <= 0 || scene.occluded(o, ls.wi, tMax, time01)) continue;
    }
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

}  // namespace

template <class Stream>
Rgb directLight(const Scene& scene, const Hit& hit, const ShadingContext& ctx, float time01, Stream& sampler,
                int vertex, int bsdfSamples, const GuideCones* guide) {
  return directLightImpl<false>(scene, hit, ctx, time01, sampler, vertex, bsdfSamples, guide, -1, nullptr);
}

template <class Stream>
Rgb directLightMedia(const Scene& scene, const Hit& hit, const ShadingContext& ctx, float time01, Stream& sampler,
                     int vertex, int bsdfSamples, const GuideCones* guide, int32_t medium, Rng& rng) {
  return directLightImpl<true>(scene, hit, ctx, time01, sampler, vertex, bsdfSamples, guide, medium, &rng);
}

template Rgb directLightMedia<RandomStream>(const Scene&, const Hit&, const ShadingContext&, float, RandomStream&, int,
                                           int, const GuideCones*, int32_t, Rng&);
template Rgb directLightMedia<SobolStream>(const Scene&, const Hit&, const ShadingContext&, float, SobolStream&, int,
                                          int, const GuideCones*, int32_t, Rng&);
template Rgb directLight<RandomStream>(const Scene&, const Hit&, const ShadingContext&, float, RandomStream&, int, int,
                                      const GuideCones*);
template Rgb directLight<SobolStream>(const Scene&, const Hit&, const ShadingContext&, float, SobolStream&, int, int,
                                     const GuideCones*);

}  // namespace tdpm
