// scene/light.h — the closed set of light sources (point, spot, directional,
// area emitters of four shapes (rectangle, sphere, disk, triangle mesh),
// environment), each of which may move, with sampling for next-event
// estimation. Photon emission sampling lives beside them (emitPhoton) so the
// photon tracer and the path tracer share one definition of every light.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "math/bounds.h"
#include "math/vec.h"
#include "motion/motion.h"
#include "scene/environment.h"

namespace tdpm {

// An area light where it is at one time (world space). Rectangle: centre,
// full edges and the emitting side's normal; disk: centre, normal, radius;
// sphere: centre, radius; mesh: its vertices' centroid and, when it moves,
// its object-to-world transform at that time.
struct AreaLightFrame {
  Vec3f center, edgeX, edgeZ, normal;
  float radius = 0;
  float area = 0;       // of the surface (one side), > 0 for a valid light
  Rgb radiance{0.0f};   // L = power / (pi area sides): Lambertian
  Affine3f toWorld;     // mesh that moves
  float areaScale = 1;  // mesh that moves: area / its area at motion step 0
};

// A triangle-mesh emitter, sampled uniformly by area through a per-triangle
// CDF (scene/area_light.cpp). Vertices are world space for a still light,
// object space for a moving one (rigid motion and uniform scale changes
// only: relative triangle areas stay those of step 0).
struct EmitterMesh {
  std::vector<Vec3f> vertices;
  std::vector<uint32_t> indices;  // 3 per triangle; counter-clockwise side emits
  std::vector<float> cdf;         // cumulative area fraction per triangle, last = 1
  float area0 = 0;                // world area at motion step 0
  float det0 = 1;                 // |det| of step 0's linear part
  Vec3f centroid{0, 0, 0};        // area-weighted, in the vertices' space
};

struct Light {
  enum class Type : uint8_t { Point, Spot, Directional, Area, Environment };
  Type type = Type::Point;
  // W (point, spot, area); W/m^2 irradiance (directional); environment:
  // the integral of its radiance over the sphere (W/m^2, see emittedPower).
  Rgb power{0.0f};
  Rgb intensity{0.0f};       // point, spot: W/sr on the axis
  Vec3f position{0, 0, 0};   // point, spot: before motion
  Vec3f direction{0, -1, 0}; // spot axis, directional travel direction: before motion
  float cosTotal = 0.0f, cosFalloffStart = 1.0f;  // spot
  // Area: its shape. Rect: size.x by size.y in the local x-z plane, emits
  // toward local -y; Disk: radius in the local x-z plane, emits toward -y;
  // Sphere: radius, emits outward; Mesh: each triangle's ccw side.
  enum class AreaShape : uint8_t { Rect, Sphere, Disk, Mesh };
  AreaShape shape = AreaShape::Rect;
  bool twoSided = false;     // area: emits from both sides (power split between them)
  bool reversed = false;     // area: emits from the other side (pbrt's ReverseOrientation)
  Vec2f size{1, 1};          // area rect
  float radius = 1;          // area sphere, disk: object space
  std::shared_ptr<const EmitterMesh> mesh;  // area mesh
  std::vector<float> stepRadius;  // sphere, disk: world radius per motion step (Embree blends them)
  std::vector<Vec3f> stepNormal;  // disk: emitting normal per motion step
  Motion motion;             // light-to-world over the shutter
  uint32_t geometryId = ~0u; // area: its Embree geometry
  // Area lights that do not move: their frame, made once by finalizeLight
  // (areaLightFrame is asked for it at every light sample and every hit).
  bool hasStillFrame = false;
  AreaLightFrame stillFrame{};
  // Environment: its radiance over directions (still: no motion).
  std::shared_ptr<const EnvironmentMap> env;

  bool isDelta() const { return type != Type::Area && type != Type::Environment; }
  // Spot falloff: 1 inside the inner cone, 0 outside the outer cone and a
  // quartic blend between (pbrt-v3's smoothstep-free form).
  float spotFalloff(float cosTheta) const;
};

// Derived constants (intensity from power; spot solid-angle integral; a
// still area light's frame). Call it again after changing a light.
void finalizeLight(Light& light);

// A light that adds nothing to any image: zero power (irradiance for a
// directional light) in every channel. Valid input, but worth a warning.
inline bool emitsNothing(const Light& light) { return !(light.power.maxComponent() > 0.0f); }

AreaLightFrame areaLightFrame(const Light& light, float time01);
// Emitted radiance of an area light leaving a point with emitting-side
// normal n (Hit::n of a ray that hit the light) along dirFromLight: the
// frame's radiance on the emitting side (both sides when twoSided), else 0.
inline Rgb areaLightRadiance(const Light& light, const AreaLightFrame& f, Vec3f n, Vec3f dirFromLight) {
  if (!light.twoSided && dot(n, dirFromLight) <= 0) return Rgb(0.0f);
  return f.radiance;
}
// The emitting-side unit normal at world point p on the light (primitive:
// the triangle of a mesh emitter), for Scene::intersect.
Vec3f areaLightNormal(const Light& light, const AreaLightFrame& f, Vec3f p, uint32_t primitive);
// A point uniform by area on the light's surface and its emitting-side
// normal (photon emission; next-event estimation but for spheres).
bool sampleAreaLightPoint(const Light& light, const AreaLightFrame& f, Vec2f u, Vec3f& q, Vec3f& n);

struct LightSample {
  Vec3f wi;            // unit, from the shading point toward the light
  float distance = 0;  // to the sampled point (infinity: directional)
  Rgb li{0.0f};        // incident radiance (area) or intensity / d^2 (delta)
  float pdf = 0;       // solid angle (area); 1 for delta lights
};

// Next-event estimation sample from shading point p at normalised time u01.
bool sampleLight(const Light& light, Vec3f p, float time01, Vec2f u, LightSample& out);
// Solid-angle density with which sampleLight would have chosen the point
// `hit` (emitting-side normal n) on an area light seen from p (for MIS when
// a BSDF-sampled ray hits it): uniform by area, but a sphere seen from
// outside is sampled uniformly over the cone it subtends (as pbrt does).
float areaLightPdf(const Light& light, const AreaLightFrame& f, Vec3f p, Vec3f hit, Vec3f n);

// Environment light: radiance from world direction w (toward the sky) and
// the solid-angle density with which sampleLight picks w.
inline Rgb environmentRadiance(const Light& light, Vec3f w) { return light.env->radiance(w); }
inline float environmentPdf(const Light& light, Vec3f w) { return light.env->pdf(w); }

// ---- photon emission ----

// The ray a photon leaves a light along. flux is the light's power over the
// density of (origin, direction) chosen, so E[flux] = emittedPower(light).
struct EmittedRay {
  Vec3f origin, direction;
  Rgb flux;
};

// Power (W) a light sends into the scene. A directional light's is its
// irradiance times the area of the disc that covers the scene's bounds; an
// environment light's is that area times the integral of its radiance over
// directions (pbrt-v4, Mitsuba), its photons leaving that disc.
Rgb emittedPower(const Light& light, const Bounds3f& sceneBounds);
// uPos, uDir: independent uniform 2D samples.
bool emitFromLight(const Light& light, float time01, const Bounds3f& sceneBounds, Vec2f uPos, Vec2f uDir,
                   EmittedRay& out);

// scene/area_light.cpp's halves of the functions above, by area shape.
AreaLightFrame computeAreaLightFrame(const Light& light, float time01);
bool sampleAreaLight(const Light& light, const AreaLightFrame& f, Vec3f p, Vec2f u, LightSample& out);
bool emitFromAreaLight(const Light& light, const AreaLightFrame& f, Vec2f uPos, Vec2f uDir, EmittedRay& out);

}  // namespace tdpm
