// scene/material.h — the closed set of materials, as flat data, and their
// classification (delta-specular vs. diffuse-like) that photon mapping needs:
// photons are stored only on surfaces with a non-delta component.
#pragma once
#include <cmath>
#include <cstdint>

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

struct Material {
  enum class Type : uint8_t { Diffuse, Mirror, Dielectric, Metal, Plastic };
  Type type = Type::Diffuse;
  Texture albedo;            // diffuse reflectance / plastic base colour
  Rgb specular{1.0f};        // mirror, metal reflectance; dielectric tint
  float ior = 1.5f;          // dielectric, plastic coating
  float alpha = 0.2f;        // GGX roughness (metal, plastic)
  // >= 0: the albedo is this node of Scene::textures (evaluated at the hit's
  // uv, scene/texture.h) instead of `albedo` above.
  int32_t albedoTexture = -1;
  // >= 0: `specular` (mirror / metal reflectance, dielectric tint) is this
  // node at the hit (Scene::shadedMaterial). Classification (isGlossy, ...)
  // does not depend on it.
  int32_t specularTexture = -1;

  // Purely delta (mirror, glass): no photon is stored here, no light sampling.
  bool isDeltaOnly() const { return type == Type::Mirror || type == Type::Dielectric; }
  // A sharp metal (GGX alpha <= kGlossyAlpha): photons treat it like a
  // mirror for the caustic map (L (S|G)+ D paths), and final-gather rays
  // pass through it to the next diffuse surface instead of estimating there.
  // Why: the light such a surface reflects onto a floor is a blurred caustic
  // that a cosine-sampled gather ray finds only when it happens to hit the
  // lamp's highlight, and then at ~100x the floor's mean (the dots beside
  // the steel post of scenes/glass-ball.json); as photons it is a smooth
  // density. Rougher metal and plastic stay diffuse-like gather surfaces.
  static constexpr float kGlossyAlpha = 0.2f;
  bool isGlossy() const { return type == Type::Metal && alpha <= kGlossyAlpha; }
  // Caustic generators: what caustic photons are aimed at and bounce on.
  bool isCausticBounce() const { return isDeltaOnly() || isGlossy(); }
  bool transmits() const { return type == Type::Dielectric; }
};

}  // namespace tdpm
