// scene/material.h — the closed set of materials, as flat data, and their
// classification (delta-specular vs. diffuse-like) that photon mapping needs:
// photons are stored only on surfaces with a non-delta component.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "math/vec.h"

namespace tdpm {

struct Texture {
  enum class Kind : uint8_t { Constant, Checker };
  Kind kind = Kind::Constant;
  Rgb a{0.8f}, b{0.2f};
  float invScale = 1.0f;

  // p in object space, so a texture moves with its object. Cells are
  // centred on the origin (the half-cell shift keeps a plane at y = 0 off a
  // cell boundary, where rounding noise would flip the parity).
  Rgb at(Vec3f p) const {
    if (kind == Kind::Constant) return a;
    int ix = int(std::floor(p.x * invScale + 0.5f));
    int iy = int(std::floor(p.y * invScale + 0.5f));
    int iz = int(std::floor(p.z * invScale + 0.5f));
    return ((ix + iy + iz) & 1) ? b : a;
  }
};

// pbrt's remaproughness, applied per hit to a textured roughness (the
// importer applies it to a constant one): pbrt-v3's polynomial in log r
// (RoughnessToAlpha of its microfacet.cpp) or pbrt-v4's sqrt(r); r = 0 stays 0.
enum class RoughnessRemap : uint8_t { None, PbrtV3, PbrtV4 };
inline float roughnessToAlpha(float r, RoughnessRemap remap) {
  if (remap == RoughnessRemap::None || r <= 0.0f) return r;
  if (remap == RoughnessRemap::PbrtV4) return std::sqrt(r);
  float x = std::log(std::max(r, 1e-3f));
  return 1.62142f + 0.819955f * x + 0.1734f * x * x + 0.0171201f * x * x * x + 0.000640711f * x * x * x * x;
}

struct Material {
  // Conductor .. Mix are pbrt's materials (issue 23; scene/bsdf_pbrt.cpp,
  // docs/scene-format.md): Conductor is a complex-IOR Fresnel conductor
  // (delta when alpha == 0), RoughDielectric a GGX microfacet dielectric
  // (Walter et al. 2007), Uber pbrt-v3's uber without its specular lobes
  // (Lambert + a GGX lobe with dielectric Fresnel), Substrate pbrt-v3's
  // Ashikhmin-Shirley, CoatedDiffuse / CoatedConductor a closed-form
  // approximation of pbrt-v4's layered BSDFs, Mix a per-hit choice between
  // two other materials (resolved by resolveMaterial before any BSDF call).
  enum class Type : uint8_t {
    Diffuse, Mirror, Dielectric, Metal, Plastic,
    Conductor, RoughDielectric, Uber, Substrate, CoatedDiffuse, CoatedConductor, Mix,
    Interface,  // no surface: a boundary between media only (no parser makes one yet)
    // pbrt-v3's matte with sigma > 0 (or a sigma texture): the Oren-Nayar
    // lobe (pbrt-v3's OrenNayar, cosine-sampled). Last, so that Diffuse
    // (sigma 0) keeps its own path in bsdf.cpp and renders as before.
    OrenNayar
  };
  Type type = Type::Diffuse;
  Texture albedo;            // diffuse reflectance / plastic, uber, substrate, coated-diffuse base colour
  Rgb specular{1.0f};        // mirror, metal reflectance; dielectric tint; uber, substrate Ks
  float ior = 1.5f;          // dielectric, plastic and coated coating, uber's Fresnel
  float alpha = 0.2f;        // GGX roughness (metal, plastic; conductor, rough dielectric, uber, substrate, coatings)
  Rgb eta{1.0f}, k{0.0f};    // conductor's complex IOR; coated conductor's, relative to the coating
  float baseAlpha = 0.0f;    // coated conductor: the conductor's GGX alpha
  float thickness = 0.01f;   // coated: the layer's optical depth along the normal (pbrt-v4's Tr)
  float coatInternal = 0.0f; // coated: the layer's cosine-averaged internal reflectance (set at build)
  float orenA = 1.0f, orenB = 0.0f;  // Oren-Nayar: pbrt-v3's A and B (orenNayarAB) for the constant sigma
  uint32_t mixOf[2] = {0, 0};  // mix: the two materials' indices
  float mixAmount = 0.5f;      // mix: probability of mixOf[1]
  bool mixDelta = false, mixCaustic = false;  // mix: a component is delta-only / a caustic bounce (set at build)
  // >= 0: the albedo is this node of Scene::textures (evaluated at the hit's
  // uv, scene/texture.h) instead of `albedo` above.
  int32_t albedoTexture = -1;
  // >= 0: `specular` (mirror / metal reflectance, dielectric tint) is this
  // node at the hit (Scene::shadedMaterial). Classification (isGlossy, ...)
  // does not depend on it.
  // A conductor's: its pbrt-v4 reflectance (per hit eta = 1, k = 2 sqrt(r) / sqrt(1 - r));
  // uber's, substrate's: Ks.
  int32_t specularTexture = -1;
  // >= 0: the GGX alpha is this float node at the hit, through
  // roughnessRemap, clamped to [1e-3, 1]. `alpha` above then holds the
  // classification alpha: the sharpest the texture's range allows
  // (scene/build.cpp, docs/scene-format.md), so isGlossy / isDeltaOnly stay
  // fixed per material.
  int32_t roughnessTexture = -1;
  int32_t baseRoughnessTexture = -1;  // coated conductor: baseAlpha per hit, as roughnessTexture
  // >= 0: a conductor's (coated conductor's) eta / k is this spectrum node
  // at the hit (pbrt-v4's SpectrumTextures), eta clamped to >= 1e-3 and k
  // to >= 0; under a coating divided by ior, as the constants are.
  int32_t etaTexture = -1, kTexture = -1;
  // >= 0: a mix's amount is this float node at the hit (pbrt-v4's
  // FloatTexture), read by resolveMaterial through Scene::materialAt.
  // With mixPerChannel a spectrum node (or, < 0, mixAmountRgb).
  int32_t amountTexture = -1;
  // A per-channel mix (pbrt-v3's Spectrum amount): f = (1 - a) f_0 + a f_1
  // per channel. Scene::materialAt picks mixOf[1] with probability p = the
  // channels' mean of a and weights the choice a / p (or (1 - a) / (1 - p)),
  // which the ShadingContext's mixWeight carries into every BSDF value: the
  // estimator's expectation is the per-channel blend.
  bool mixPerChannel = false;
  Rgb mixAmountRgb{0.5f};
  // >= 0: Oren-Nayar's sigma (degrees, clamped to [0, 90] as pbrt-v3) is
  // this float node at the hit; orenA / orenB then come from it per hit.
  int32_t sigmaTexture = -1;
  // >= 0: a coating's thickness is this float node at the hit (pbrt-v4's
  // FloatTexture; build.cpp refuses a texture whose range reaches below 0).
  int32_t thicknessTexture = -1;
  // >= 0: a dielectric's (rough dielectric's, uber's) ior is this float
  // node at the hit (pbrt-v3's glass and uber eta FloatTextures), kept >= 1;
  // build.cpp refuses a texture whose range reaches below 1.
  int32_t iorTexture = -1;
  RoughnessRemap roughnessRemap = RoughnessRemap::None;
  // Shading normals (scene/shading_normal.cpp): >= 0, a float node of
  // Scene::textures displacing the surface along its normal by bumpScale x
  // its value (pbrt's bump map), or an image of Scene::textures holding a
  // tangent-space normal map (pbrt-v4's normalmap; the map wins when both
  // are given, as in pbrt-v4). Neither: the geometric normal, as always.
  int32_t bumpTexture = -1;
  float bumpScale = 1.0f;
  int32_t normalMapImage = -1;
  bool hasShadingNormal() const { return bumpTexture >= 0 || normalMapImage >= 0; }

  // Purely delta (mirror, glass, smooth conductor): no photon is stored
  // here, no light sampling.
  bool isDeltaOnly() const {
    return type == Type::Mirror || type == Type::Dielectric || (type == Type::Conductor && alpha == 0.0f);
  }
  // A sharp metal (GGX alpha <= kGlossyAlpha): photons treat it like a
  // mirror for the caustic map (L (S|G)+ D paths), and final-gather rays
  // pass through it to the next diffuse surface instead of estimating there.
  // Why: the light such a surface reflects onto a floor is a blurred caustic
  // that a cosine-sampled gather ray finds only when it happens to hit the
  // lamp's highlight, and then at ~100x the floor's mean (the dots beside
  // the steel post of scenes/glass-ball.json); as photons it is a smooth
  // density. Rougher metal and plastic stay diffuse-like gather surfaces.
  static constexpr float kGlossyAlpha = 0.2f;
  // A rough dielectric is always one: a gather point on it would estimate
  // only the photons on the viewer's side, never the light it transmits.
  bool isGlossy() const {
    return ((type == Type::Metal || type == Type::Conductor) && alpha <= kGlossyAlpha && !isDeltaOnly()) ||
           type == Type::RoughDielectric;
  }
  // Caustic generators: what caustic photons are aimed at and bounce on.
  bool isCausticBounce() const { return isDeltaOnly() || isGlossy(); }
  bool transmits() const { return type == Type::Dielectric || type == Type::RoughDielectric; }
  // A photon-map target: this material or (mix) one of its components is
  // delta-only (glossy: or a caustic bounce).
  bool causticTarget(bool glossy) const { return glossy ? isCausticBounce() || mixCaustic : isDeltaOnly() || mixDelta; }
};

// pbrt-v3's OrenNayar constructor: sigma in degrees (clamped to [0, 90], as
// pbrt-v3's MatteMaterial clamps its texture), A and B of the qualitative
// model (Oren and Nayar 1994). sigma 0: A = 1, B = 0, Lambert's values.
inline void orenNayarAB(float sigmaDegrees, float* A, float* B) {
  float s = std::clamp(sigmaDegrees, 0.0f, 90.0f) * (kPi / 180.0f);
  float s2 = s * s;
  *A = 1.0f - s2 / (2.0f * (s2 + 0.33f));
  *B = 0.45f * s2 / (s2 + 0.09f);
}

// The material a hit uses: a mix material picks one of its two per hit,
// deterministically from the point and direction (as pbrt-v4's MixMaterial
// hashes them), with probability amount(mix) for the second; mixes of mixes
// resolve in turn, each level with its own hash (a shared one would tie the
// inner choice to the outer). Material indices stay out of the hash: a
// scene and its `tdpm convert` JSON number materials differently.
// amount(const Material&) -> float: the mix's amount at this hit (its
// constant, or its texture there: Scene::materialAt); asked only of mixes.
// chosen(const Material& mix, bool second, float amount): told each choice
// (a per-channel mix's weight, Scene::materialAt).
template <class Amount, class Chosen>
inline const Material& resolveMaterial(const Material* materials, uint32_t index, Vec3f p, Vec3f wo, Amount amount,
                                       Chosen chosen) {
  const Material* m = materials + index;
  if (m->type != Material::Type::Mix) return *m;
  float v[6] = {p.x, p.y, p.z, wo.x, wo.y, wo.z};
  uint64_t h = 0x9E3779B97F4A7C15ull;
  for (float f : v) {
    uint32_t bits;
    std::memcpy(&bits, &f, 4);
    h = (h ^ bits) * 0xFF51AFD7ED558CCDull;
    h ^= h >> 33;
  }
  while (m->type == Material::Type::Mix) {
    h += 0x9E3779B97F4A7C15ull;  // splitmix64: one value per level
    uint64_t z = h;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    float u = float(z >> 40) * 0x1p-24f;  // [0, 1)
    // pbrt-v4: amount <= 0 is the first, >= 1 the second, else amount < u the first.
    float a = amount(*m);
    bool second = !(a < u || a <= 0.0f);
    chosen(*m, second, a);
    m = materials + (second ? m->mixOf[1] : m->mixOf[0]);
  }
  return *m;
}
template <class Amount>
inline const Material& resolveMaterial(const Material* materials, uint32_t index, Vec3f p, Vec3f wo, Amount amount) {
  return resolveMaterial(materials, index, p, wo, amount, [](const Material&, bool, float) {});
}
// Constant amounts only (tests, and materials without an amount texture).
inline const Material& resolveMaterial(const Material* materials, uint32_t index, Vec3f p, Vec3f wo) {
  return resolveMaterial(materials, index, p, wo, [](const Material& m) { return m.mixAmount; });
}

}  // namespace tdpm
