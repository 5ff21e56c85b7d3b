// scene/light.h — the closed set of light sources (point, spot, directional,
// rectangular area, environment), each of which may move, with sampling for next-event
// estimation. Photon emission sampling lives beside them (emitPhoton) so the
// photon tracer and the path tracer share one definition of every light.
#pragma once
#include <cstdint>
#include <memory>

#include "math/bounds.h"
#include "math/vec.h"
#include "motion/motion.h"
#include "scene/environment.h"

namespace tdpm {

struct AreaLightFrame {
  Vec3f center, edgeX, edgeZ, normal;  // world, at one time; normal = emitting side
  float area;
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
  Vec2f size{1, 1};          // area: local x-z rectangle, emits toward local -y
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
// Emitted radiance of an area light toward direction -wiToLight from the
// light's surface, when its emitting side faces it.
Rgb areaLightRadiance(const Light& light, const AreaLightFrame& f, Vec3f dirFromLight);

struct LightSample {
  Vec3f wi;            // unit, from the shading point toward the light
  float distance = 0;  // to the sampled point (infinity: directional)
  Rgb li{0.0f};        // incident radiance (area) or intensity / d^2 (delta)
  float pdf = 0;       // solid angle (area); 1 for delta lights
};

// Next-event estimation sample from shading point p at normalised time u01.
bool sampleLight(const Light& light, Vec3f p, float time01, Vec2f u, LightSample& out);
// Solid-angle density with which sampleLight would have chosen the point
// `hit` on an area light (for MIS when a BSDF-sampled ray hits it).
float areaLightPdf(const Light& light, const AreaLightFrame& f, Vec3f p, Vec3f hit);

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

}  // namespace tdpm
