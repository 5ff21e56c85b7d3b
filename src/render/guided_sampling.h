// render/guided_sampling.h — the path tracer's one-sample mixture of BSDF
// sampling and a guide made of cones of directions (render/caustic_guide.h
// fills the cones from caustic photons).
//
// With probability c a direction is drawn uniformly from one cone (chosen
// in proportion to its solid angle), otherwise from the BSDF. The density
// of the mixture (Veach's balance heuristic over the two strategies) is
//     p(w) = (1 - c) p_bsdf(w) + c N(w) / Omega,
// N(w) = number of cones holding w, Omega = the cones' total solid angle.
// The BSDF term covers every direction the BSDF scatters to, so the
// estimate f |cos| / p(w) stays unbiased whatever the cones are; they only
// decide how much variance is saved. Next-event estimation's MIS weight
// uses the same p(w) for the BSDF side (render/direct_light.h), and so does
// the emission a continuation ray hits.
//
// No cones (fraction 0) means plain BSDF sampling, drawn and weighed
// exactly as without a guide.
#pragma once
#include <array>

#include "math/vec.h"
#include "scene/bsdf.h"

namespace tdpm {

struct GuideCones {
  static constexpr int kMaxCones = 32;
  // A cone is tested by chord length, |w - axis|^2 <= 2 (1 - cos theta_max),
  // not by the cosine: for the sub-degree cones of a focused caustic
  // 1 - cos is ~1e-5, and a float dot product near 1 would misjudge the
  // cone's rim, where a sampled direction found outside its own cone gets a
  // density far too small (a firefly, and bias).
  struct Cone {
    Vec3f axis;
    float oneMinusCos;
    float solidAngle;
    bool holds(Vec3f w) const { return lengthSquared(w - axis) <= 2.0f * oneMinusCos; }
  };
  std::array<Cone, kMaxCones> cone;
  int count = 0;
  float totalSolidAngle = 0;
  float fraction = 0;  // c; 0 when there is no cone

  bool active() const { return fraction > 0.0f; }
  // Mixture density of direction w, given the BSDF's density of it.
  float pdf(float bsdfPdf, Vec3f w) const {
    if (!active()) return bsdfPdf;
    int inside = 0;
    for (int i = 0; i < count; ++i) inside += cone[size_t(i)].holds(w);
    return (1.0f - fraction) * bsdfPdf + fraction * float(inside) / totalSolidAngle;
  }
};

// Draws the continuation direction from the mixture. u (2D) and uLobe are
// the vertex's kBsdf group as bsdfSample takes them: uLobe < c picks the
// guide (and, rescaled, its cone), the rest is rescaled for the BSDF's own
// lobe choice, so no sample dimension is added. out.weight = f |cos| / p(w),
// out.pdf = p(w). Without an active guide this is bsdfSample itself.
bool guidedBsdfSample(const ShadingContext& ctx, const GuideCones& cones, Vec2f u, float uLobe, BsdfSample& out);

}  // namespace tdpm
