// scene/quadric.h — the analytic disk and cylinder (pbrt's `disk` and
// `cylinder` shapes) in their own object space: ray intersection, the
// outward normal, and bounds. scene/embree_scene.cpp traces them as Embree
// user geometry (the ray is taken to object space, so any affine placement
// and the blended motion of motion/motion.h are exact); scene/scene.cpp
// turns a hit into a normal. Frames are pbrt's, not the quad's x-z plane:
//   disk:     z = height, innerRadius <= sqrt(x^2 + y^2) <= radius, normal +z
//   cylinder: x^2 + y^2 = radius^2, zMin <= z <= zMax, normal outward
// Both keep only the points with phi = atan2(y, x) in [0, phiMax] (phi
// taken in [0, 2 pi)), as pbrt does.
#pragma once
#include <cstdint>

#include "math/bounds.h"
#include "math/vec.h"

namespace tdpm {

struct Quadric {
  enum class Kind : uint8_t { Disk, Cylinder };
  Kind kind = Kind::Disk;
  float radius = 1.0f;
  float innerRadius = 0.0f;       // disk
  float height = 0.0f;            // disk: its plane z = height
  float zMin = -1.0f, zMax = 1.0f;  // cylinder
  float phiMax = 6.28318530717958647692f;  // radians, (0, 2 pi]
};

// The smallest s in (tNear, tFar) where o + s d meets the surface (o, d in
// object space; d need not be unit, so s is the world ray's parameter when
// both were mapped by the same affine inverse). Double precision inside: a
// cylinder's quadratic cancels badly in float for rays from far away.
bool intersectQuadric(const Quadric& q, Vec3f o, Vec3f d, float tNear, float tFar, float& s);
// The outward (un-reversed) unit normal at object-space point p on the surface.
Vec3f quadricNormal(const Quadric& q, Vec3f p);
// Object-space bounds (the whole disk / cylinder, whatever phiMax).
Bounds3f quadricBounds(const Quadric& q);
// The surface area (for tests and light sampling).
float quadricArea(const Quadric& q);

}  // namespace tdpm
