// scene/bsdf.cpp — Lambert, perfect mirror, Fresnel dielectric, GGX metal
// and a Lambert-under-GGX-coating plastic; pbrt's materials are passed on
// to scene/bsdf_pbrt.cpp.
#include "scene/bsdf.h"

#include <algorithm>
#include <cmath>

#include "sampling/warp.h"
#include "scene/bsdf_pbrt.h"

namespace tdpm {

namespace {

Vec3f reflectLocal(Vec3f w) { return {-w.x, -w.y, w.z}; }
Vec3f reflectAbout(Vec3f w, Vec3f h) { return h * (2.0f * dot(w, h)) - w; }

// ---- GGX (Trowbridge-Reitz), isotropic, Smith separable masking ----
float ggxD(Vec3f h, float alpha) {
  float c2 = h.z * h.z;
  float a2 = alpha * alpha;
  float d = c2 * (a2 - 1.0f) + 1.0f;
  return a2 / (kPi * d * d);
}
float ggxG1(Vec3f v, float alpha) {
  float c = std::fabs(v.z);
  float a2 = alpha * alpha;
  return 2.0f * c / (c + std::sqrt(a2 + (1.0f - a2) * c * c));
}
// Samples a half vector with density D(h) cos(theta_h).
Vec3f ggxSampleH(Vec2f u, float alpha) {
  float tan2 = alpha * alpha * u.x / std::max(1e-7f, 1.0f - u.x);
  float cosT = 1.0f / std::sqrt(1.0f + tan2);
  float sinT = std::sqrt(std::max(0.0f, 1.0f - cosT * cosT));
  float phi = 2.0f * kPi * u.y;
  return {sinT * std::cos(phi), sinT * std::sin(phi), cosT};
}
float ggxPdfWi(Vec3f wo, Vec3f wi, float alpha) {
  Vec3f h = normalize(wo + wi);
  float ho = std::fabs(dot(wo, h));
  if (ho == 0) return 0;
  return ggxD(h, alpha) * h.z / (4.0f * ho);
}
Rgb schlick(Rgb f0, float cosT) {
  float m = std::clamp(1.0f - cosT, 0.0f, 1.0f);
  float m5 = (m * m) * (m * m) * m;
  return f0 + (Rgb(1.0f) - f0) * m5;
}

// Microfacet reflection f for a given Fresnel value at the half vector.
float ggxReflection(Vec3f wo, Vec3f wi, float alpha) {
  Vec3f h = normalize(wo + wi);
  return ggxD(h, alpha) * ggxG1(wo, alpha) * ggxG1(wi, alpha) / (4.0f * wo.z * wi.z);
}

constexpr float kPlasticSpecularProbability = 0.5f;

}  // namespace

float fresnelDielectric(float cosI, float eta) {
  cosI = std::clamp(cosI, 0.0f, 1.0f);
  float sin2T = (1.0f - cosI * cosI) / (eta * eta);
  if (sin2T >= 1.0f) return 1.0f;  // total internal reflection
  float cosT = std::sqrt(1.0f - sin2T);
  float rs = (cosI - eta * cosT) / (cosI + eta * cosT);
  float rp = (eta * cosI - cosT) / (eta * cosI + cosT);
  return 0.5f * (rs * rs + rp * rp);
}

ShadingContext makeShadingContext(const Material& m, Rgb albedo, Vec3f outwardNormal, Vec3f woWorld) {
  Vec3f n = m.transmits() ? outwardNormal : faceForward(outwardNormal, woWorld);
  ShadingContext c{&m, albedo, Frame(n), {}};
  c.woLocal = c.frame.toLocal(woWorld);
  return c;
}

ShadingContext makeShadingContext(const Material& m, Rgb albedo, Vec3f outwardNormal, Vec3f woWorld, Vec3f ns) {
  float wg = dot(woWorld, outwardNormal), ws = dot(woWorld, ns);
  if ((wg > 0) != (ws > 0) || ws == 0.0f) return makeShadingContext(m, albedo, outwardNormal, woWorld);
  bool flip = !m.transmits() && wg < 0;
  ShadingContext c{&m, albedo, Frame(flip ? -ns : ns), {}};
  c.woLocal = c.frame.toLocal(woWorld);
  c.shaded = true;
  c.ng = flip ? -outwardNormal : outwardNormal;
  return c;
}

namespace {
Rgb evalComponent(const ShadingContext& c, Vec3f wiWorld) {
  Vec3f wo = c.woLocal, wi = c.frame.toLocal(wiWorld);
  const Material& m = *c.material;
  if (c.shaded && !c.sidesAgree(wiWorld)) return Rgb(0.0f);
  if (m.type >= Material::Type::Conductor) return pbrtBsdfEval(c, wo, wi);  // pbrt's materials: bsdf_pbrt.cpp
  if (wo.z <= 0 || wi.z <= 0) return Rgb(0.0f);
  switch (m.type) {
    case Material::Type::Diffuse:
      return c.albedo * kInvPi;
    case Material::Type::Metal: {
      Vec3f h = normalize(wo + wi);
      return schlick(m.specular, dot(wi, h)) * ggxReflection(wo, wi, m.alpha);
    }
    case Material::Type::Plastic: {
      Vec3f h = normalize(wo + wi);
      float fs = fresnelDielectric(dot(wi, h), m.ior);
      float diffuseScale = (1.0f - fresnelDielectric(wo.z, m.ior)) * (1.0f - fresnelDielectric(wi.z, m.ior));
      return c.albedo * (diffuseScale * kInvPi) + Rgb(fs * ggxReflection(wo, wi, m.alpha));
    }
    default:  // mirror, dielectric: delta only
      return Rgb(0.0f);
  }
}
bool sampleComponent(const ShadingContext& c, Vec2f u, float uLobe, Transport mode, BsdfSample& out);
}  // namespace

Rgb bsdfEval(const ShadingContext& c, Vec3f wiWorld) {
  Rgb f = evalComponent(c, wiWorld);
  return c.mixWeighted ? f * c.mixWeight : f;
}

bool bsdfSample(const ShadingContext& c, Vec2f u, float uLobe, Transport mode, BsdfSample& out) {
  if (!sampleComponent(c, u, uLobe, mode, out)) return false;
  if (c.mixWeighted) out.weight = out.weight * c.mixWeight;
  return true;
}

float bsdfPdf(const ShadingContext& c, Vec3f wiWorld) {
  Vec3f wo = c.woLocal, wi = c.frame.toLocal(wiWorld);
  const Material& m = *c.material;
  if (c.shaded && !c.sidesAgree(wiWorld)) return 0.0f;
  if (m.type >= Material::Type::Conductor) return pbrtBsdfPdf(c, wo, wi);
  if (wo.z <= 0 || wi.z <= 0) return 0.0f;
  switch (m.type) {
    case Material::Type::Diffuse: return cosineHemispherePdf(wi.z);
    case Material::Type::Metal: return ggxPdfWi(wo, wi, m.alpha);
    case Material::Type::Plastic:
      return kPlasticSpecularProbability * ggxPdfWi(wo, wi, m.alpha) +
             (1.0f - kPlasticSpecularProbability) * cosineHemispherePdf(wi.z);
    default: return 0.0f;
  }
}

float dielectricBranches(const ShadingContext& c, Transport mode, BsdfSample& reflected, BsdfSample& refracted) {
  // Reuses bsdfSample's two lobes: uLobe 0 always reflects, and just
  // below 1 refracts unless total internal reflection (F = 1) forbids it.
  const Material& m = *c.material;
  Vec3f wo = c.woLocal;
  float eta = wo.z > 0 ? m.ior : 1.0f / m.ior;
  float F = fresnelDielectric(std::fabs(wo.z), eta);
  // A branch the shading normal turns to the wrong geometric side carries nothing (bsdf.h).
  if (!bsdfSample(c, {0, 0}, 0.0f, mode, reflected)) reflected.weight = Rgb(0.0f);
  if (!bsdfSample(c, {0, 0}, std::nextafter(1.0f, 0.0f), mode, refracted)) refracted.weight = Rgb(0.0f);
  return F;
}

namespace {
// bsdfSample without the per-channel mix's weight (bsdfSample applies it once).
bool sampleComponent(const ShadingContext& c, Vec2f u, float uLobe, Transport mode, BsdfSample& out) {
  if (c.shaded) {
    // As below, then the shading and geometric normals must agree (bsdf.h).
    ShadingContext plain = c;
    plain.shaded = false;
    return sampleComponent(plain, u, uLobe, mode, out) && c.sidesAgree(out.wi);
  }
  const Material& m = *c.material;
  Vec3f wo = c.woLocal;
  switch (m.type) {
    case Material::Type::Mirror: {
      if (wo.z <= 0) return false;
      out = {c.frame.toWorld(reflectLocal(wo)), m.specular, 0.0f, true};
      return true;
    }
    case Material::Type::Dielectric: {
      bool entering = wo.z > 0;
      float eta = entering ? m.ior : 1.0f / m.ior;  // eta_t / eta_i
      float cosO = std::fabs(wo.z);
      float F = fresnelDielectric(cosO, eta);
      if (uLobe < F) {  // reflect (always under total internal reflection)
        out = {c.frame.toWorld(reflectLocal(wo)), m.specular, 0.0f, true};
        return true;
      }
      float sin2T = (1.0f - cosO * cosO) / (eta * eta);
      float cosT = std::sqrt(std::max(0.0f, 1.0f - sin2T));
      Vec3f wt{-wo.x / eta, -wo.y / eta, entering ? -cosT : cosT};
      float scale = mode == Transport::Radiance ? 1.0f / (eta * eta) : 1.0f;
      out = {c.frame.toWorld(normalize(wt)), m.specular * scale, 0.0f, true};
      return true;
    }
    case Material::Type::Diffuse: {
      if (wo.z <= 0) return false;
      Vec3f wi = squareToCosineHemisphere(u);
      if (wi.z <= 0) return false;
      out = {c.frame.toWorld(wi), c.albedo, cosineHemispherePdf(wi.z), false};
      return true;
    }
    case Material::Type::Metal:
    case Material::Type::Plastic: {
      if (wo.z <= 0) return false;
      Vec3f wi;
      if (m.type == Material::Type::Metal || uLobe < kPlasticSpecularProbability) {
        wi = reflectAbout(wo, ggxSampleH(u, m.alpha));
      } else {
        wi = squareToCosineHemisphere(u);
      }
      if (wi.z <= 0) return false;
      Vec3f wiWorld = c.frame.toWorld(wi);
      float pdf = bsdfPdf(c, wiWorld);
      if (!(pdf > 0)) return false;
      out = {wiWorld, evalComponent(c, wiWorld) * (wi.z / pdf), pdf, false};
      return true;
    }
    default: return pbrtBsdfSample(c, u, uLobe, mode, out);
  }
}
}  // namespace

}  // namespace tdpm
