// scene/area_light.cpp — the four area-light shapes (rectangle, sphere,
// disk, triangle mesh): where each is at a time, points uniform by area on
// it, its normal at a hit, its emitted radiance and the solid-angle density
// of next-event estimation (also asked for MIS when a BSDF ray hits it).
// One switch on Light::AreaShape per call: no virtual calls per sample.
#include <algorithm>
#include <cmath>

#include "math/frame.h"
#include "sampling/warp.h"
#include "scene/light.h"

namespace tdpm {

namespace {

// Embree's blend of a per-step value (sphere and disk radii, disk normals)
// at normalised time u: the same segment choice as Motion::atNormalized.
template <class T>
T blendSteps(const std::vector<T>& v, float u) {
  if (v.size() == 1) return v[0];
  float s = std::clamp(u, 0.0f, 1.0f) * float(v.size() - 1);
  int i = std::min(int(s), int(v.size()) - 2);
  float f = s - float(i);
  return v[size_t(i)] * (1.0f - f) + v[size_t(i) + 1] * f;
}

Vec3f triangleNormal(const EmitterMesh& m, uint32_t t) {
  Vec3f a = m.vertices[m.indices[3 * t]], b = m.vertices[m.indices[3 * t + 1]], c = m.vertices[m.indices[3 * t + 2]];
  return cross(b - a, c - a);
}

}  // namespace

AreaLightFrame computeAreaLightFrame(const Light& light, float time01) {
  Affine3f m = light.motion.atNormalized(time01);
  AreaLightFrame f;
  f.center = m.point({0, 0, 0});
  float sign = light.reversed ? -1.0f : 1.0f;
  switch (light.shape) {
    case Light::AreaShape::Rect: {
      f.edgeX = m.vector({light.size.x, 0, 0});
      f.edgeZ = m.vector({0, 0, light.size.y});
      Vec3f c = cross(f.edgeZ, f.edgeX);  // local (0,0,1) x (1,0,0) = +y; emitting side is -y
      f.area = length(c);
      f.normal = (f.area > 0 ? -c / f.area : Vec3f(0, -1, 0)) * sign;
      break;
    }
    case Light::AreaShape::Disk: {
      f.radius = blendSteps(light.stepRadius, time01);
      f.normal = normalize(blendSteps(light.stepNormal, time01)) * sign;
      f.area = kPi * f.radius * f.radius;
      break;
    }
    case Light::AreaShape::Sphere:
      f.radius = blendSteps(light.stepRadius, time01);
      f.area = 4.0f * kPi * f.radius * f.radius;
      break;
    case Light::AreaShape::Mesh: {
      const EmitterMesh& mesh = *light.mesh;
      if (light.motion.moving()) {
        f.toWorld = m;
        // Rigid motion with uniform scale changes: every area scales alike.
        f.areaScale = std::pow(std::fabs(m.determinant3()) / mesh.det0, 2.0f / 3.0f);
        f.center = m.point(mesh.centroid);
      } else {
        f.center = mesh.centroid;  // already world space
      }
      f.area = mesh.area0 * f.areaScale;
      break;
    }
  }
  if (f.area > 0 && std::isfinite(f.area)) f.radiance = light.power / (kPi * f.area * (light.twoSided ? 2.0f : 1.0f));
  return f;
}

Vec3f areaLightNormal(const Light& light, const AreaLightFrame& f, Vec3f p, uint32_t primitive) {
  float sign = light.reversed ? -1.0f : 1.0f;
  switch (light.shape) {
    case Light::AreaShape::Rect:
    case Light::AreaShape::Disk: return f.normal;
    case Light::AreaShape::Sphere: return normalize(p - f.center) * sign;
    case Light::AreaShape::Mesh: {
      Vec3f n = triangleNormal(*light.mesh, primitive);
      if (light.motion.moving()) n = f.toWorld.normal(n);
      float len = length(n);
      return len > 0 ? n * (sign / len) : Vec3f(0, 1, 0);
    }
  }
  return f.normal;
}

bool sampleAreaLightPoint(const Light& light, const AreaLightFrame& f, Vec2f u, Vec3f& q, Vec3f& n) {
  if (!(f.area > 0)) return false;
  float sign = light.reversed ? -1.0f : 1.0f;
  switch (light.shape) {
    case Light::AreaShape::Rect:
      q = f.center + f.edgeX * (u.x - 0.5f) + f.edgeZ * (u.y - 0.5f);
      n = f.normal;
      return true;
    case Light::AreaShape::Disk: {
      Frame fr(f.normal);
      Vec2f d = squareToConcentricDisk(u);
      q = f.center + (fr.s * d.x + fr.t * d.y) * f.radius;
      n = f.normal;
      return true;
    }
    case Light::AreaShape::Sphere: {
      Vec3f w = squareToUniformSphere(u);
      q = f.center + w * f.radius;
      n = w * sign;
      return true;
    }
    case Light::AreaShape::Mesh: {
      const EmitterMesh& m = *light.mesh;
      // The triangle by area, then u.x rescaled within its CDF bin.
      size_t t = size_t(std::upper_bound(m.cdf.begin(), m.cdf.end(), u.x) - m.cdf.begin());
      t = std::min(t, m.cdf.size() - 1);
      float lo = t ? m.cdf[t - 1] : 0.0f, width = m.cdf[t] - lo;
      float ux = width > 0 ? std::min((u.x - lo) / width, 0.99999994f) : 0.5f;
      float su = std::sqrt(ux);
      float b0 = 1.0f - su, b1 = u.y * su;
      Vec3f a = m.vertices[m.indices[3 * t]], b = m.vertices[m.indices[3 * t + 1]], c = m.vertices[m.indices[3 * t + 2]];
      q = a * b0 + b * b1 + c * (1.0f - b0 - b1);
      Vec3f nn = cross(b - a, c - a);
      if (light.motion.moving()) {
        q = f.toWorld.point(q);
        nn = f.toWorld.normal(nn);
      }
      float len = length(nn);
      if (!(len > 0)) return false;
      n = nn * (sign / len);
      return true;
    }
  }
  return false;
}

namespace {

// A sphere seen from outside: the cosine of the half-angle of the cone it
// subtends, and 1 - that cosine without cancellation (r << d: the tiny
// lights of veach-mis are 0.05 m at ~10 m).
bool sphereCone(const AreaLightFrame& f, Vec3f p, float& dc, float& sin2Max, float& oneMinusCos) {
  float dc2 = lengthSquared(p - f.center);
  float r2 = f.radius * f.radius;
  if (!(dc2 > r2 * 1.00001f)) return false;  // inside or on it: area sampling
  dc = std::sqrt(dc2);
  sin2Max = r2 / dc2;
  float cosMax = std::sqrt(std::max(0.0f, 1.0f - sin2Max));
  oneMinusCos = sin2Max / (1.0f + cosMax);
  return oneMinusCos > 0;
}

float areaToSolidAngle(const AreaLightFrame& f, Vec3f p, Vec3f hit, Vec3f n) {
  Vec3f d = hit - p;
  float dist2 = lengthSquared(d);
  float cosL = std::fabs(dot(n, d)) / std::sqrt(dist2);
  if (!(cosL > 0) || !(f.area > 0)) return 0.0f;
  return dist2 / (cosL * f.area);
}

}  // namespace

float areaLightPdf(const Light& light, const AreaLightFrame& f, Vec3f p, Vec3f hit, Vec3f n) {
  if (light.shape == Light::AreaShape::Sphere) {
    float dc, sin2, omc;
    if (sphereCone(f, p, dc, sin2, omc)) return 1.0f / (2.0f * kPi * omc);
  }
  return areaToSolidAngle(f, p, hit, n);
}

// Next-event estimation of an area light (light.cpp's sampleLight).
bool sampleAreaLight(const Light& light, const AreaLightFrame& f, Vec3f p, Vec2f u, LightSample& out) {
  Vec3f q, n;
  float dc, sin2, omc;
  if (light.shape == Light::AreaShape::Sphere && sphereCone(f, p, dc, sin2, omc)) {
    // Uniform in the cone (pbrt's Sphere::Sample): cos theta = 1 - u (1 - cos max),
    // and the direction's first hit on the sphere.
    Vec3f wc = (f.center - p) / dc;
    float oneMinusCosT = u.x * omc;
    float cosT = 1.0f - oneMinusCosT;
    float sin2T = oneMinusCosT * (2.0f - oneMinusCosT);
    float sinT = std::sqrt(std::max(0.0f, sin2T));
    float phi = 2.0f * kPi * u.y;
    Frame fr(wc);
    out.wi = fr.toWorld({sinT * std::cos(phi), sinT * std::sin(phi), cosT});
    // Distance to the near intersection: dc cos - sqrt(r^2 - dc^2 sin^2),
    // with r^2 - dc^2 sin^2 = dc^2 (sin2Max - sin2T) (no cancellation).
    float h = dc * std::sqrt(std::max(0.0f, sin2 - sin2T));
    out.distance = std::max(0.0f, dc * cosT - h);
    q = p + out.wi * out.distance;
    n = normalize(q - f.center) * (light.reversed ? -1.0f : 1.0f);
    out.li = areaLightRadiance(light, f, n, -out.wi);
    out.pdf = 1.0f / (2.0f * kPi * omc);
    return !out.li.isBlack() && out.distance > 0;
  }
  if (light.shape == Light::AreaShape::Rect) {
    // The common case without the point sampler's call and switch (the
    // same arithmetic as sampleAreaLightPoint's rectangle).
    if (!(f.area > 0)) return false;
    q = f.center + f.edgeX * (u.x - 0.5f) + f.edgeZ * (u.y - 0.5f);
    n = f.normal;
  } else if (!sampleAreaLightPoint(light, f, u, q, n)) {
    return false;
  }
  Vec3f d = q - p;
  float dist2 = lengthSquared(d);
  if (!(dist2 > 0)) return false;
  out.distance = std::sqrt(dist2);
  out.wi = d / out.distance;
  out.li = areaLightRadiance(light, f, n, -out.wi);
  if (out.li.isBlack()) return false;
  out.pdf = areaToSolidAngle(f, p, q, n);
  return out.pdf > 0;
}

// Photon emission: uniform by area, cosine-weighted over the emitting
// hemisphere (a twosided light picks a side with probability 1/2), so
// flux = L pi A sides = power.
bool emitFromAreaLight(const Light& light, const AreaLightFrame& f, Vec2f uPos, Vec2f uDir, EmittedRay& out) {
  Vec3f q, n;
  if (!sampleAreaLightPoint(light, f, uPos, q, n)) return false;
  if (light.twoSided) {
    if (uDir.x < 0.5f) {
      uDir.x *= 2.0f;
    } else {
      uDir.x = std::min(2.0f * uDir.x - 1.0f, 0.99999994f);
      n = -n;
    }
  }
  out.origin = q;
  out.direction = Frame(n).toWorld(squareToCosineHemisphere(uDir));
  out.flux = light.power;
  return true;
}

}  // namespace tdpm
