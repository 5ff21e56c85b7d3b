// render/guided_sampling.h — sampling with a guide made of cones of
// directions: the path tracer's one-sample mixture with BSDF sampling
// (render/caustic_guide.h fills the cones from caustic photons) and the
// final gather's BSDF/guide pair (its cones from global photons).
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
// The final gather (render/photon_integrator.cpp) uses the cones another
// way: each gather ray is a pair, one BSDF sample and one guide sample,
// each weighed by p_bsdf(w) + p_guide(w) (multi-sample MIS, balance
// heuristic; guidedPairSample), with cones of per-photon widths each drawn
// with probability 1/count (perCone). In a gap between cones the mixture
// doubles a BSDF sample's weight (at c = 0.5); the pair leaves it as it is.
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
    float density = 0.0f;  // perCone: 1 / (count x solidAngle)
    bool holds(Vec3f w) const { return lengthSquared(w - axis) <= 2.0f * oneMinusCos; }
  };
  std::array<Cone, kMaxCones> cone;
  int count = 0;
  float totalSolidAngle = 0;
  float fraction = 0;  // c; 0 when there is no cone
  // false: a cone is picked in proportion to its solid angle (the caustic
  // guide's equal cones), density c N(w) / Omega. true: each cone is picked
  // with probability 1 / count whatever its size (the gather guide's cones
  // of per-photon widths, one per photon of about equal flux), density
  // c sum over the cones holding w of 1 / (count Omega_i).
  bool perCone = false;
  // Multi-sample MIS (Veach's balance heuristic over one BSDF sample and
  // one guide sample, guidedPairSample): the density a sample is weighed by
  // is p_bsdf + p_guide, and c only switches the guide on.
  bool multi = false;

  bool active() const { return fraction > 0.0f; }
  // No cones, as a fresh GuideCones (the cones' storage is left as it is:
  // the path tracer keeps one per thread rather than building 32 cones at
  // every vertex, which cost 2.6% of a path-traced Cornell box).
  void clear() {
    count = 0;
    totalSolidAngle = 0;
    fraction = 0;
    perCone = false;
    multi = false;
  }
  // Mixture density of direction w, given the BSDF's density of it.
  float pdf(float bsdfPdf, Vec3f w) const {
    if (!active()) return bsdfPdf;
    if (perCone) {
      float g = 0.0f;
      for (int i = 0; i < count; ++i)
        if (cone[size_t(i)].holds(w)) g += cone[size_t(i)].density;
      return multi ? bsdfPdf + g : (1.0f - fraction) * bsdfPdf + fraction * g;
    }
    int inside = 0;
    for (int i = 0; i < count; ++i) inside += cone[size_t(i)].holds(w);
    float g = float(inside) / totalSolidAngle;
    return multi ? bsdfPdf + g : (1.0f - fraction) * bsdfPdf + fraction * g;
  }
};

// Draws the continuation direction from the mixture. u (2D) and uLobe are
// the vertex's kBsdf group as bsdfSample takes them: uLobe < c picks the
// guide (and, rescaled, its cone), the rest is rescaled for the BSDF's own
// lobe choice, so no sample dimension is added. out.weight = f |cos| / p(w),
// out.pdf = p(w). Without an active guide this is bsdfSample itself.
bool guidedBsdfSample(const ShadingContext& ctx, const GuideCones& cones, Vec2f u, float uLobe, BsdfSample& out);

// With cones.multi: sample `which` (0: the BSDF's, 1: the guide's) of a
// pair whose two values, each f |cos| / (p_bsdf + p_guide), sum to an
// unbiased estimate of the integral (the balance heuristic with one sample
// per strategy). Where the guide has no density the BSDF sample alone
// carries f |cos| / p_bsdf, as without a guide: a guide that misses adds no
// variance there (the one-sample mixture doubled the weight in its gaps).
bool guidedPairSample(const ShadingContext& ctx, const GuideCones& cones, int which, Vec2f u, float uLobe,
                      BsdfSample& out);

}  // namespace tdpm
