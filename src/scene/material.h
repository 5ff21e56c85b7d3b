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

  // Purely delta (mirror, glass): no photon is stored here, no light sampling.
  bool isDeltaOnly() const { return type == Type::Mirror || type == Type::Dielectric; }
  bool transmits() const { return type == Type::Dielectric; }
};

}  // namespace tdpm
