// scene/light.cpp — light constants, next-event sampling and photon emission
// (area lights' shapes: scene/area_light.cpp).
#include "scene/light.h"

#include <cmath>
#include <limits>

#include "math/frame.h"
#include "sampling/warp.h"

namespace tdpm {

float Light::spotFalloff(float cosTheta) const {
  if (cosTheta >= cosFalloffStart) return 1.0f;
  if (cosTheta <= cosTotal) return 0.0f;
  float d = (cosTheta - cosTotal) / (cosFalloffStart - cosTotal);
  return (d * d) * (d * d);
}


void finalizeLight(Light& light) {
  switch (light.type) {
    case Light::Type::Point:
      light.intensity = light.power / (4.0f * kPi);
      break;
    case Light::Type::Spot: {
      // Power = I * integral of the falloff over the sphere
      //       = I * 2 pi [(1 - cosFalloffStart) + (cosFalloffStart - cosTotal) / 5],
      // the quartic blend integrating to 1/5 of its band (exact, unlike
      // pbrt's midpoint approximation), so the stated watts are emitted.
      float solid = 2.0f * kPi * ((1.0f - light.cosFalloffStart) + (light.cosFalloffStart - light.cosTotal) / 5.0f);
      light.intensity = light.power / solid;
      break;
    }
    case Light::Type::Directional:
    case Light::Type::Area:
      break;
    case Light::Type::Environment:
      if (light.env) light.power = light.env->integral();
      break;
  }
  light.hasStillFrame = false;
  if (light.type == Light::Type::Area && !light.motion.moving()) {
    light.stillFrame = computeAreaLightFrame(light, 0.0f);  // a still motion is the same at every time
    light.hasStillFrame = true;
  }
}


AreaLightFrame areaLightFrame(const Light& light, float time01) {
  if (light.hasStillFrame) return light.stillFrame;
  return computeAreaLightFrame(light, time01);
}

namespace {

// Direction and distance from the shading point p to a point q on a light;
// false when they coincide.
bool aimAt(Vec3f p, Vec3f q, LightSample& out) {
  Vec3f d = q - p;
  float dist2 = lengthSquared(d);
  if (!(dist2 > 0)) return false;
  out.distance = std::sqrt(dist2);
  out.wi = d / out.distance;
  return true;
}

}  // namespace

bool sampleLight(const Light& light, Vec3f p, float time01, Vec2f u, LightSample& out) {
  switch (light.type) {
    case Light::Type::Point:
    case Light::Type::Spot: {
      Affine3f m = light.motion.atNormalized(time01);
      if (!aimAt(p, m.point(light.position), out)) return false;
      out.pdf = 1.0f;
      Rgb i = light.intensity;
      if (light.type == Light::Type::Spot) {
        Vec3f axis = normalize(m.vector(light.direction));
        float f = light.spotFalloff(dot(-out.wi, axis));
        if (f <= 0) return false;
        i = i * f;
      }
      out.li = i / (out.distance * out.distance);
      return true;
    }
    case Light::Type::Directional: {
      Affine3f m = light.motion.atNormalized(time01);
      out.wi = -normalize(m.vector(light.direction));
      out.distance = std::numeric_limits<float>::infinity();
      out.li = light.power;
      out.pdf = 1.0f;
      return true;
    }
    case Light::Type::Area:
      // A still light's frame by reference: copying it per sample was a
      // measurable part of next-event estimation.
      if (light.hasStillFrame) return sampleAreaLight(light, light.stillFrame, p, u, out);
      return sampleAreaLight(light, computeAreaLightFrame(light, time01), p, u, out);
    case Light::Type::Environment:
      out.distance = std::numeric_limits<float>::infinity();
      return light.env->sample(u, out.wi, out.li, out.pdf);
  }
  return false;
}

namespace {

// Bounding sphere of the scene: a directional light emits over the disc of
// this radius facing it, from outside the sphere.
void boundingSphere(const Bounds3f& b, Vec3f& centre, float& radius) {
  if (b.empty()) { centre = {0, 0, 0}; radius = 1.0f; return; }
  centre = b.center();
  radius = std::max(1e-6f, 0.5f * length(b.diagonal()) * 1.001f);
}

}  // namespace

Rgb emittedPower(const Light& light, const Bounds3f& sceneBounds) {
  if (light.type == Light::Type::Directional || light.type == Light::Type::Environment) {
    Vec3f c;
    float r;
    boundingSphere(sceneBounds, c, r);
    return light.power * (kPi * r * r);
  }
  return light.power;
}

bool emitFromLight(const Light& light, float time01, const Bounds3f& sceneBounds, Vec2f uPos, Vec2f uDir,
                   EmittedRay& out) {
  switch (light.type) {
    case Light::Type::Point: {
      Affine3f m = light.motion.atNormalized(time01);
      out.origin = m.point(light.position);
      out.direction = squareToUniformSphere(uDir);
      out.flux = light.intensity * (1.0f / kUniformSpherePdf);  // = power
      return true;
    }
    case Light::Type::Spot: {
      // Uniform over the outer cone; the falloff goes into the flux, so
      // E[flux] = I * integral of the falloff = power.
      Affine3f m = light.motion.atNormalized(time01);
      Frame f(normalize(m.vector(light.direction)));
      Vec3f local = squareToUniformCone(uDir, light.cosTotal);
      float falloff = light.spotFalloff(local.z);
      if (falloff <= 0) return false;
      out.origin = m.point(light.position);
      out.direction = f.toWorld(local);
      out.flux = light.intensity * (falloff / uniformConePdf(light.cosTotal));
      return true;
    }
    case Light::Type::Directional: {
      Affine3f m = light.motion.atNormalized(time01);
      Vec3f d = normalize(m.vector(light.direction));
      Vec3f c;
      float r;
      boundingSphere(sceneBounds, c, r);
      Frame f(d);
      Vec2f disk = squareToConcentricDisk(uPos);
      out.origin = c + (f.s * disk.x + f.t * disk.y) * r - d * r;
      out.direction = d;
      out.flux = light.power * (kPi * r * r);
      return true;
    }
    case Light::Type::Area: return emitFromAreaLight(light, areaLightFrame(light, time01), uPos, uDir, out);
    case Light::Type::Environment: {
      // A direction toward the sky by the map's luminance, then a point on
      // the disc of the bounding sphere perpendicular to it, outside the
      // sphere: E[flux] = pi r^2 * integral of L = emittedPower.
      Vec3f w;
      Rgb L;
      float pdf;
      if (!light.env->sample(uDir, w, L, pdf)) return false;
      Vec3f c;
      float r;
      boundingSphere(sceneBounds, c, r);
      Frame f(w);
      Vec2f disk = squareToConcentricDisk(uPos);
      out.origin = c + (f.s * disk.x + f.t * disk.y) * r + w * r;
      out.direction = -w;
      out.flux = L * (kPi * r * r / pdf);
      return true;
    }
  }
  return false;
}

}  // namespace tdpm
