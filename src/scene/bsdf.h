// scene/bsdf.h — scattering at a surface point for each Material type:
// evaluation, density and importance sampling, in a local shading frame
// (z = normal). One switch per call over the closed set; no virtual calls.
//
// Conventions: wo points away from the surface toward the viewer (or the
// previous vertex), wi toward the next vertex / the light. `n` given to
// makeShadingFrame is the outward geometric normal; opaque materials are
// two-sided (the frame is flipped to wo's side), dielectrics are not.
#pragma once
#include <cmath>

#include "math/frame.h"
#include "math/vec.h"
#include "scene/material.h"

namespace tdpm {

// Radiance (eye paths) vs. importance (photon paths): refraction scales
// radiance by (eta_i / eta_t)^2 but not importance (Veach 1997, ch. 5).
enum class Transport : uint8_t { Radiance, Importance };

struct ShadingContext {
  const Material* material;
  Rgb albedo;   // texture evaluated at the hit
  Frame frame;  // world <-> local (z: the shading normal)
  Vec3f woLocal;
  // A shading normal (bump / normal map) made the frame: ng is the
  // geometric normal on the frame's side, and a direction scatters only
  // when both normals agree on whether it is a reflection or a
  // transmission (pbrt-v3's BSDF::f rule), so a bumped surface never lets
  // light through from behind it nor reflects into itself.
  bool shaded = false;
  Vec3f ng{0.0f, 0.0f, 1.0f};
  bool sidesAgree(Vec3f wiWorld) const {
    return ((dot(woWorld(), ng) > 0) == (dot(wiWorld, ng) > 0)) == ((woLocal.z > 0) == (dot(wiWorld, frame.n) > 0));
  }
  Vec3f woWorld() const { return frame.toWorld(woLocal); }
  // A per-channel mix's weight for the component chosen at this hit
  // (Material::mixPerChannel, Scene::materialAt): bsdfEval and bsdfSample
  // scale their values by it when mixWeighted; pdfs are the component's.
  bool mixWeighted = false;
  Rgb mixWeight{1.0f};
};

// Builds the context at a hit: flips the frame toward wo unless the
// material transmits.
ShadingContext makeShadingContext(const Material& m, Rgb albedo, Vec3f outwardNormal, Vec3f woWorld);
// The same about a shading normal ns (unit, on outwardNormal's side):
// flipped with the geometric normal toward wo unless the material
// transmits. When wo is on the other side of ns than of the geometric
// normal (a grazing view of a steep bump), the geometric frame is used:
// the BSDFs see wo below their surface there and would give black.
ShadingContext makeShadingContext(const Material& m, Rgb albedo, Vec3f outwardNormal, Vec3f woWorld, Vec3f ns);

// Photons through shading normals (vertex normals, bump and normal maps):
// the BSDF is not symmetric there, and light paths need Veach's adjoint
// (thesis sec. 5.3; pbrt-v3's CorrectShadingNormal). A photon arriving from
// wPrev (unit, pointing away from the surface) and leaving along wNext
// carries bsdfSample's weight times |wPrev.ns| |wNext.ng| / (|wPrev.ng|
// |wNext.ns|); 1 without a shading normal (or 0 where it vanishes).
inline float adjointShadingFactor(const ShadingContext& c, Vec3f wPrev, Vec3f wNext) {
  if (!c.shaded) return 1.0f;
  float num = std::fabs(dot(wPrev, c.frame.n)) * std::fabs(dot(wNext, c.ng));
  float den = std::fabs(dot(wPrev, c.ng)) * std::fabs(dot(wNext, c.frame.n));
  return den > 0 ? num / den : 0.0f;
}
// A photon density estimate's BSDF at a shading normal: stored photons are
// flux through the geometric surface (|wi.ng| dA), the radiance integral
// weighs incident light by |wi.ns|: f |wi.ns| / |wi.ng| (1 when !shaded).
inline float gatherShadingFactor(const ShadingContext& c, Vec3f wi) {
  if (!c.shaded) return 1.0f;
  float den = std::fabs(dot(wi, c.ng));
  return den > 0 ? std::fabs(dot(wi, c.frame.n)) / den : 0.0f;
}

struct BsdfSample {
  Vec3f wi;        // world
  Rgb weight;      // f * |cos| / pdf (delta: the reflectance / transmittance)
  float pdf = 0;   // solid angle; 0 for delta lobes' "infinite" density
  bool delta = false;
};

// f(wo, wi) for non-delta lobes (delta lobes contribute 0 here).
Rgb bsdfEval(const ShadingContext& c, Vec3f wiWorld);
float bsdfPdf(const ShadingContext& c, Vec3f wiWorld);
// u: 2D sample; uLobe: lobe choice. Returns false if the path ends.
bool bsdfSample(const ShadingContext& c, Vec2f u, float uLobe, Transport mode, BsdfSample& out);

// A dielectric's two delta branches at once (for splitting instead of the
// Fresnel choice): the reflected and refracted directions, each with the
// weight bsdfSample gives it when chosen, and the Fresnel reflectance F, the
// probability bsdfSample chooses reflection. F = 1 under total internal
// reflection (then `refracted` is the reflection too).
float dielectricBranches(const ShadingContext& c, Transport mode, BsdfSample& reflected, BsdfSample& refracted);

// Unpolarised Fresnel reflectance of a dielectric interface; cosI is the
// cosine on the incident side, eta = eta_transmitted / eta_incident.
float fresnelDielectric(float cosI, float eta);

}  // namespace tdpm
