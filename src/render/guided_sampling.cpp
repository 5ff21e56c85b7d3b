// render/guided_sampling.cpp — sampling the BSDF/guide mixture.
#include "render/guided_sampling.h"

#include <algorithm>
#include <cmath>

#include "math/frame.h"
#include "sampling/warp.h"

namespace tdpm {

namespace {
// A direction uniform in one cone (index from uPick in [0, 1)), weighed by
// the density cones.pdf gives it.
bool coneSample(const ShadingContext& ctx, const GuideCones& cones, float uPick, Vec2f u, BsdfSample& out) {
  int i = 0;
  if (cones.perCone) {
    i = std::min(int(uPick * float(cones.count)), cones.count - 1);
  } else {
    float pick = uPick * cones.totalSolidAngle;
    while (i + 1 < cones.count && pick >= cones.cone[size_t(i)].solidAngle) pick -= cones.cone[size_t(i++)].solidAngle;
  }
  const GuideCones::Cone& k = cones.cone[size_t(i)];
  // Uniform in the cap, from 1 - cos directly (no 1 - cosMax cancellation);
  // the sampled height is pulled in by 1e-4 of the cap so that rounding
  // never puts the direction outside its own cone (density error 1e-4).
  float h = u.x * k.oneMinusCos * (1.0f - 1e-4f);
  float sinT = std::sqrt(std::max(0.0f, h * (2.0f - h)));
  float phi = 2.0f * kPi * u.y;
  Vec3f w = Frame(k.axis).toWorld({sinT * std::cos(phi), sinT * std::sin(phi), 1.0f - h});
  Rgb f = bsdfEval(ctx, w);
  float cosTheta = std::fabs(dot(w, ctx.frame.n));
  // Below the horizon (or where the BSDF is 0) this sample's value is 0.
  if (f.isBlack() || !(cosTheta > 0.0f)) return false;
  float p = cones.pdf(bsdfPdf(ctx, w), w);
  out.wi = w;
  out.pdf = p;
  out.weight = f * (cosTheta / p);
  out.delta = false;
  return true;
}
}  // namespace

bool guidedPairSample(const ShadingContext& ctx, const GuideCones& cones, int which, Vec2f u, float uLobe,
                      BsdfSample& out) {
  if (which == 1) return coneSample(ctx, cones, uLobe, u, out);
  if (!bsdfSample(ctx, u, uLobe, Transport::Radiance, out)) return false;
  if (out.delta) return true;
  float p = cones.pdf(out.pdf, out.wi);
  out.weight = out.weight * (out.pdf / p);
  out.pdf = p;
  return true;
}

bool guidedBsdfSample(const ShadingContext& ctx, const GuideCones& cones, Vec2f u, float uLobe, BsdfSample& out) {
  if (!cones.active()) return bsdfSample(ctx, u, uLobe, Transport::Radiance, out);
  const float c = cones.fraction;
  if (uLobe < c) return coneSample(ctx, cones, uLobe / c, u, out);
  float uRest = std::min((uLobe - c) / (1.0f - c), 0x1.fffffep-1f);
  if (!bsdfSample(ctx, u, uRest, Transport::Radiance, out)) return false;
  if (out.delta) return true;  // no density to mix (the guide serves diffuse-like materials only)
  float p = cones.pdf(out.pdf, out.wi);
  out.weight = out.weight * (out.pdf / p);
  out.pdf = p;
  return true;
}

}  // namespace tdpm
