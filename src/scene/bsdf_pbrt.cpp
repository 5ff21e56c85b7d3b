// scene/bsdf_pbrt.cpp — pbrt's materials as tdpm BSDFs: the complex-IOR
// conductor and the rough dielectric as pbrt-v4 has them, pbrt-v3's uber
// (non-specular lobes), substrate (Ashikhmin-Shirley FresnelBlend) and
// matte with sigma > 0 (Oren-Nayar), and
// closed-form stand-ins for pbrt-v4's stochastic layered coateddiffuse and
// coatedconductor (docs/scene-format.md says how they are built and
// tests/test_materials.cpp measures them against a random walk through the
// layer). Every lobe's pdf is the density its sampler draws from.
#include "scene/bsdf_pbrt.h"

#include <algorithm>
#include <cmath>
#include <complex>

#include "sampling/warp.h"

namespace tdpm {

namespace ggx {

namespace {
float lambda(Vec3f w, float alpha) {
  float c2 = w.z * w.z;
  if (c2 == 0.0f) return 0.0f;  // pbrt: tan = inf gives 0 (G is then 0 through the cosines)
  float tan2 = std::max(0.0f, 1.0f - c2) / c2;
  return 0.5f * (std::sqrt(1.0f + alpha * alpha * tan2) - 1.0f);
}
}  // namespace

float D(Vec3f wm, float alpha) {
  float c2 = wm.z * wm.z;
  float a2 = alpha * alpha;
  float d = c2 * (a2 - 1.0f) + 1.0f;
  return a2 / (kPi * d * d);
}
float G(Vec3f wo, Vec3f wi, float alpha) { return 1.0f / (1.0f + lambda(wo, alpha) + lambda(wi, alpha)); }
float visiblePdf(Vec3f w, Vec3f wm, float alpha) {
  float c = std::fabs(w.z);
  if (c == 0.0f) return 0.0f;
  return D(wm, alpha) * std::fabs(dot(w, wm)) / ((1.0f + lambda(w, alpha)) * c);
}
Vec3f sampleVisible(Vec3f w, Vec2f u, float alpha) {
  Vec3f wh = normalize(Vec3f{alpha * w.x, alpha * w.y, w.z});
  if (wh.z < 0) wh = -wh;
  Vec3f t1 = wh.z < 0.99999f ? normalize(cross(Vec3f{0, 0, 1}, wh)) : Vec3f{1, 0, 0};
  Vec3f t2 = cross(wh, t1);
  float r = std::sqrt(u.x), phi = 2.0f * kPi * u.y;
  float px = r * std::cos(phi), py = r * std::sin(phi);
  float h = std::sqrt(std::max(0.0f, 1.0f - px * px));
  float s = 0.5f * (1.0f + wh.z);
  py = (1.0f - s) * h + s * py;
  float pz = std::sqrt(std::max(0.0f, 1.0f - px * px - py * py));
  Vec3f nh = t1 * px + t2 * py + wh * pz;
  return normalize(Vec3f{alpha * nh.x, alpha * nh.y, std::max(1e-6f, nh.z)});
}

}  // namespace ggx

namespace {

using T = Material::Type;

Vec3f reflectAbout(Vec3f w, Vec3f h) { return h * (2.0f * dot(w, h)) - w; }
float pow5(float x) { return (x * x) * (x * x) * x; }

// Refracts w (pointing away from the surface, on n's side) through the
// interface with normal n (eta = eta_t / eta_i); false under total
// internal reflection.
bool refract(Vec3f w, Vec3f n, float eta, Vec3f& wt) {
  float cosI = dot(n, w);
  if (cosI < 0) {
    eta = 1.0f / eta;
    cosI = -cosI;
    n = -n;
  }
  float sin2T = std::max(0.0f, 1.0f - cosI * cosI) / (eta * eta);
  if (sin2T >= 1.0f) return false;
  float cosT = std::sqrt(1.0f - sin2T);
  wt = -w / eta + n * (cosI / eta - cosT);
  return true;
}

Rgb conductorFresnel(const Material& m, float cosI) {
  return {fresnelConductor(cosI, m.eta.r, m.k.r), fresnelConductor(cosI, m.eta.g, m.k.g),
          fresnelConductor(cosI, m.eta.b, m.k.b)};
}

// GGX reflection f (without Fresnel) and its sampling density.
float microfacetReflection(Vec3f wo, Vec3f wi, Vec3f wm, float alpha) {
  return ggx::D(wm, alpha) * ggx::G(wo, wi, alpha) / (4.0f * wo.z * wi.z);
}
float microfacetReflectionPdf(Vec3f wo, Vec3f wm, float alpha) {
  float ho = std::fabs(dot(wo, wm));
  return ho > 0 ? ggx::visiblePdf(wo, wm, alpha) / (4.0f * ho) : 0.0f;
}

// ---- rough dielectric (pbrt-v4 DielectricBxDF, rough branch) ----
// The half vector of (wo, wi), facing +z, or false for a degenerate or
// back-facing configuration; etap: the relative index of a refraction.
bool dielectricHalf(Vec3f wo, Vec3f wi, float eta, Vec3f& wm, float& etap) {
  bool reflect = wo.z * wi.z > 0;
  etap = reflect ? 1.0f : (wo.z > 0 ? eta : 1.0f / eta);
  wm = wi * etap + wo;
  if (wi.z == 0 || wo.z == 0 || lengthSquared(wm) == 0) return false;
  wm = normalize(wm);
  if (wm.z < 0) wm = -wm;
  return !(dot(wm, wi) * wi.z < 0 || dot(wm, wo) * wo.z < 0);
}

Rgb roughDielectricEval(const Material& m, Vec3f wo, Vec3f wi) {
  Vec3f wm;
  float etap;
  if (!dielectricHalf(wo, wi, m.ior, wm, etap)) return Rgb(0.0f);
  float F = fresnelDielectricSigned(dot(wo, wm), m.ior);
  float g = ggx::G(wo, wi, m.alpha), d = ggx::D(wm, m.alpha);
  if (wo.z * wi.z > 0) return m.specular * (d * g * F / std::fabs(4.0f * wi.z * wo.z));
  float denom = dot(wi, wm) + dot(wo, wm) / etap;
  denom = denom * denom * wi.z * wo.z;
  float ft = d * (1.0f - F) * g * std::fabs(dot(wi, wm) * dot(wo, wm) / denom);
  return m.specular * (ft / (etap * etap));  // radiance: eval serves eye paths and shadow rays
}

float roughDielectricPdf(const Material& m, Vec3f wo, Vec3f wi) {
  Vec3f wm;
  float etap;
  if (!dielectricHalf(wo, wi, m.ior, wm, etap)) return 0.0f;
  float R = fresnelDielectricSigned(dot(wo, wm), m.ior), Tr = 1.0f - R;
  if (wo.z * wi.z > 0) return microfacetReflectionPdf(wo, wm, m.alpha) * R;
  float denom = dot(wi, wm) + dot(wo, wm) / etap;
  float dwmdwi = std::fabs(dot(wi, wm)) / (denom * denom);
  return ggx::visiblePdf(wo, wm, m.alpha) * dwmdwi * Tr;
}

bool roughDielectricSample(const ShadingContext& c, Vec2f u, float uLobe, Transport mode, BsdfSample& out) {
  const Material& m = *c.material;
  Vec3f wo = c.woLocal;
  if (wo.z == 0) return false;
  // The microfacet normal faces +z (pbrt-v4: from inside, dot(wo, wm) < 0
  // and the Fresnel and the refraction invert eta).
  Vec3f wm = ggx::sampleVisible(wo, u, m.alpha);
  float R = fresnelDielectricSigned(dot(wo, wm), m.ior);
  Vec3f wi;
  if (uLobe < R) {
    wi = reflectAbout(wo, wm);
    if (wo.z * wi.z <= 0) return false;
  } else {
    if (!refract(wo, wm, m.ior, wi)) return false;
    wi = normalize(wi);
    if (wo.z * wi.z >= 0 || wi.z == 0) return false;
  }
  float pdf = roughDielectricPdf(m, wo, wi);
  if (!(pdf > 0)) return false;
  Rgb f = roughDielectricEval(m, wo, wi);
  if (mode == Transport::Importance && wo.z * wi.z < 0) {
    float etap = wo.z > 0 ? m.ior : 1.0f / m.ior;
    f = f * (etap * etap);  // importance is not scaled by the refraction
  }
  out = {c.frame.toWorld(wi), f * (std::fabs(wi.z) / pdf), pdf, false};
  return true;
}

// ---- layered stand-ins ----
// Up-going direction inside a coating of index eta that leaves along w.
Vec3f insideDirection(Vec3f w, float eta) {
  Vec3f v{w.x / eta, w.y / eta, 0.0f};
  v.z = std::sqrt(std::max(0.0f, 1.0f - v.x * v.x - v.y * v.y));
  return v;
}
float layerTransmittance(const Material& m, Vec3f inside) { return std::exp(-m.thickness / inside.z); }

// The light that crosses the coating both ways: (1 - F_o)(1 - F_i) / eta^2
// and the layer's absorption along both refracted directions.
float coatThrough(const Material& m, Vec3f wo, Vec3f wi, Vec3f woIn, Vec3f wiIn) {
  float t = (1.0f - fresnelDielectric(wo.z, m.ior)) * (1.0f - fresnelDielectric(wi.z, m.ior));
  return t * layerTransmittance(m, woIn) * layerTransmittance(m, wiIn) / (m.ior * m.ior);
}

float coatSpecular(const Material& m, Vec3f wo, Vec3f wi, Vec3f wm) {
  return fresnelDielectric(dot(wi, wm), m.ior) * microfacetReflection(wo, wi, wm, m.alpha);
}

constexpr float kCoatSpecularProbability = 0.5f;

Rgb coatedDiffuseEval(const ShadingContext& c, Vec3f wo, Vec3f wi) {
  const Material& m = *c.material;
  Vec3f wm = normalize(wo + wi);
  Vec3f woIn = insideDirection(wo, m.ior), wiIn = insideDirection(wi, m.ior);
  // Diffuse light bouncing between the base and the coating's underside:
  // a geometric series in albedo x internal reflectance x the round trip's
  // absorption (exp(-2 thickness) per crossing: 1 / cos averages 2 over a
  // cosine-weighted hemisphere).
  float trip = m.coatInternal * std::exp(-4.0f * m.thickness);
  Rgb series = {1.0f / (1.0f - c.albedo.r * trip), 1.0f / (1.0f - c.albedo.g * trip),
                1.0f / (1.0f - c.albedo.b * trip)};
  return c.albedo * series * (coatThrough(m, wo, wi, woIn, wiIn) * kInvPi) + Rgb(coatSpecular(m, wo, wi, wm));
}

// The coated conductor's base lobe: the conductor (index relative to the
// coating) between the refracted directions, and its sampling density
// carried out through the interface (d omega_in / d omega = cos / (eta^2 cos_in)).
Rgb coatedConductorBase(const Material& m, Vec3f wo, Vec3f wi, float* pdf) {
  Vec3f woIn = insideDirection(wo, m.ior), wiIn = insideDirection(wi, m.ior);
  Vec3f wm = normalize(woIn + wiIn);
  if (pdf) *pdf = microfacetReflectionPdf(woIn, wm, m.baseAlpha) * wi.z / (m.ior * m.ior * wiIn.z);
  return conductorFresnel(m, std::fabs(dot(woIn, wm))) *
         (microfacetReflection(woIn, wiIn, wm, m.baseAlpha) * coatThrough(m, wo, wi, woIn, wiIn));
}

// pbrt-v3's OrenNayar::f / (R / pi): A + B max(0, cos(phi_i - phi_o))
// sin(alpha) tan(beta), alpha the larger polar angle, beta the smaller.
float orenNayarFactor(const Material& m, Vec3f wo, Vec3f wi) {
  float sinI = std::sqrt(std::max(0.0f, 1.0f - wi.z * wi.z)), sinO = std::sqrt(std::max(0.0f, 1.0f - wo.z * wo.z));
  float maxCos = 0.0f;
  if (sinI > 1e-4f && sinO > 1e-4f) maxCos = std::clamp((wi.x * wo.x + wi.y * wo.y) / (sinI * sinO), 0.0f, 1.0f);
  float sinAlpha, tanBeta;
  if (wi.z > wo.z) {
    sinAlpha = sinO;
    tanBeta = sinI / wi.z;
  } else {
    sinAlpha = sinI;
    tanBeta = sinO / wo.z;
  }
  return m.orenA + m.orenB * maxCos * sinAlpha * tanBeta;
}

float uberSpecularProbability(const ShadingContext& c) {
  bool d = !c.albedo.isBlack(), s = !c.material->specular.isBlack();
  return s ? (d ? 0.5f : 1.0f) : 0.0f;
}

}  // namespace

float fresnelConductor(float cosI, float eta, float k) {
  cosI = std::clamp(cosI, 0.0f, 1.0f);
  std::complex<float> e(eta, k);
  float sin2I = 1.0f - cosI * cosI;
  std::complex<float> sin2T = sin2I / (e * e);
  std::complex<float> cosT = std::sqrt(1.0f - sin2T);
  std::complex<float> rParl = (e * cosI - cosT) / (e * cosI + cosT);
  std::complex<float> rPerp = (cosI - e * cosT) / (cosI + e * cosT);
  return 0.5f * (std::norm(rParl) + std::norm(rPerp));
}

float fresnelDielectricSigned(float cosI, float eta) {
  if (cosI < 0) {
    eta = 1.0f / eta;
    cosI = -cosI;
  }
  return fresnelDielectric(cosI, eta);
}

float coatInternalReflectance(float eta) {
  // F_ext averaged by 2 mu d mu (midpoint rule; F is smooth in mu).
  constexpr int kSteps = 4096;
  double sum = 0;
  for (int i = 0; i < kSteps; ++i) {
    double mu = (i + 0.5) / kSteps;
    sum += 2.0 * mu * fresnelDielectric(float(mu), eta) / kSteps;
  }
  return float(1.0 - (1.0 - sum) / (double(eta) * eta));
}

Rgb pbrtBsdfEval(const ShadingContext& c, Vec3f wo, Vec3f wi) {
  const Material& m = *c.material;
  if (m.type == T::RoughDielectric) return roughDielectricEval(m, wo, wi);
  if (wo.z <= 0 || wi.z <= 0) return Rgb(0.0f);
  Vec3f wm = normalize(wo + wi);
  switch (m.type) {
    case T::Conductor:
      if (m.alpha == 0.0f) return Rgb(0.0f);
      return conductorFresnel(m, dot(wo, wm)) * microfacetReflection(wo, wi, wm, m.alpha);
    case T::Uber: {
      Rgb f = c.albedo * kInvPi;
      if (!m.specular.isBlack()) f += m.specular * coatSpecular(m, wo, wi, wm);
      return f;
    }
    case T::Substrate: {
      Rgb rd = c.albedo, rs = m.specular;
      float k = (28.0f / (23.0f * kPi)) * (1.0f - pow5(1.0f - 0.5f * wi.z)) * (1.0f - pow5(1.0f - 0.5f * wo.z));
      Rgb diffuse = rd * (Rgb(1.0f) - rs) * k;
      float hi = std::fabs(dot(wi, wm));
      Rgb schlick = rs + (Rgb(1.0f) - rs) * pow5(1.0f - dot(wi, wm));
      return diffuse + schlick * (ggx::D(wm, m.alpha) / (4.0f * hi * std::max(wi.z, wo.z)));
    }
    case T::CoatedDiffuse: return coatedDiffuseEval(c, wo, wi);
    case T::CoatedConductor:
      return coatedConductorBase(m, wo, wi, nullptr) + Rgb(coatSpecular(m, wo, wi, wm));
    case T::OrenNayar: return c.albedo * (kInvPi * orenNayarFactor(m, wo, wi));
    default: return Rgb(0.0f);
  }
}

float pbrtBsdfPdf(const ShadingContext& c, Vec3f wo, Vec3f wi) {
  const Material& m = *c.material;
  if (m.type == T::RoughDielectric) return roughDielectricPdf(m, wo, wi);
  if (wo.z <= 0 || wi.z <= 0) return 0.0f;
  Vec3f wm = normalize(wo + wi);
  switch (m.type) {
    case T::Conductor: return m.alpha == 0.0f ? 0.0f : microfacetReflectionPdf(wo, wm, m.alpha);
    case T::Uber: {
      float ps = uberSpecularProbability(c);
      return ps * microfacetReflectionPdf(wo, wm, m.alpha) + (1.0f - ps) * cosineHemispherePdf(wi.z);
    }
    case T::Substrate:
    case T::CoatedDiffuse:
      return kCoatSpecularProbability * microfacetReflectionPdf(wo, wm, m.alpha) +
             (1.0f - kCoatSpecularProbability) * cosineHemispherePdf(wi.z);
    case T::CoatedConductor: {
      float base;
      coatedConductorBase(m, wo, wi, &base);
      return kCoatSpecularProbability * microfacetReflectionPdf(wo, wm, m.alpha) +
             (1.0f - kCoatSpecularProbability) * base;
    }
    case T::OrenNayar: return cosineHemispherePdf(wi.z);  // pbrt-v3's BxDF::Sample_f: cosine-weighted
    default: return 0.0f;
  }
}

bool pbrtBsdfSample(const ShadingContext& c, Vec2f u, float uLobe, Transport mode, BsdfSample& out) {
  const Material& m = *c.material;
  if (m.type == T::RoughDielectric) return roughDielectricSample(c, u, uLobe, mode, out);
  Vec3f wo = c.woLocal;
  if (wo.z <= 0) return false;
  Vec3f wi;
  switch (m.type) {
    case T::Conductor:
      if (m.alpha == 0.0f) {  // smooth: a mirror with the conductor's Fresnel
        out = {c.frame.toWorld(Vec3f{-wo.x, -wo.y, wo.z}), conductorFresnel(m, wo.z), 0.0f, true};
        return true;
      }
      wi = reflectAbout(wo, ggx::sampleVisible(wo, u, m.alpha));
      break;
    case T::Uber:
    case T::Substrate:
    case T::CoatedDiffuse: {
      float ps = m.type == T::Uber ? uberSpecularProbability(c) : kCoatSpecularProbability;
      if (m.type == T::Uber && ps == 0.0f && c.albedo.isBlack()) return false;
      wi = uLobe < ps ? reflectAbout(wo, ggx::sampleVisible(wo, u, m.alpha)) : squareToCosineHemisphere(u);
      break;
    }
    case T::CoatedConductor:
      if (uLobe < kCoatSpecularProbability) {
        wi = reflectAbout(wo, ggx::sampleVisible(wo, u, m.alpha));
      } else {
        Vec3f woIn = insideDirection(wo, m.ior);
        Vec3f wiIn = reflectAbout(woIn, ggx::sampleVisible(woIn, u, m.baseAlpha));
        if (wiIn.z <= 0) return false;
        float sx = wiIn.x * m.ior, sy = wiIn.y * m.ior, s2 = sx * sx + sy * sy;
        if (s2 >= 1.0f) return false;  // trapped in the coating (total internal reflection)
        wi = {sx, sy, std::sqrt(1.0f - s2)};
      }
      break;
    case T::OrenNayar: wi = squareToCosineHemisphere(u); break;
    default: return false;
  }
  if (wi.z <= 0) return false;
  Vec3f wiWorld = c.frame.toWorld(wi);
  float pdf = pbrtBsdfPdf(c, wo, wi);
  if (!(pdf > 0)) return false;
  out = {wiWorld, pbrtBsdfEval(c, wo, wi) * (wi.z / pdf), pdf, false};
  return true;
}

}  // namespace tdpm
