// scene/quadric.cpp — disk and cylinder intersection, normals and bounds
// (scene/quadric.h).
#include "scene/quadric.h"

#include <algorithm>
#include <cmath>

namespace tdpm {

namespace {

constexpr double kTwoPi = 6.28318530717958647692;

// pbrt's phi test: phi = atan2(y, x) in [0, 2 pi) must not exceed phiMax.
bool insidePhi(const Quadric& q, double x, double y) {
  if (q.phiMax >= float(kTwoPi)) return true;
  double phi = std::atan2(y, x);
  if (phi < 0) phi += kTwoPi;
  return phi <= double(q.phiMax);
}

bool diskHit(const Quadric& q, Vec3f o, Vec3f d, float tNear, float tFar, float& s) {
  if (d.z == 0.0f) return false;  // parallel to the plane: no hit (pbrt does the same)
  double t = (double(q.height) - o.z) / double(d.z);
  if (!(t > tNear && t < tFar)) return false;
  double x = o.x + t * d.x, y = o.y + t * d.y;
  double r2 = x * x + y * y;
  double R = q.radius, Ri = q.innerRadius;
  if (r2 > R * R || r2 < Ri * Ri) return false;
  if (!insidePhi(q, x, y)) return false;
  s = float(t);
  return s > tNear && s < tFar;
}

bool cylinderHit(const Quadric& q, Vec3f o, Vec3f d, float tNear, float tFar, float& s) {
  double ox = o.x, oy = o.y, dx = d.x, dy = d.y;
  double a = dx * dx + dy * dy;
  if (a == 0.0) return false;  // along the axis: the side is never met
  double b = 2.0 * (dx * ox + dy * oy);
  double c = ox * ox + oy * oy - double(q.radius) * q.radius;
  double disc = b * b - 4.0 * a * c;
  if (disc < 0.0) return false;
  // The numerically stable pair of roots (no cancellation in either).
  double root = std::sqrt(disc);
  double qq = b < 0 ? -0.5 * (b - root) : -0.5 * (b + root);
  double t0 = qq / a, t1 = qq != 0.0 ? c / qq : t0;
  if (t0 > t1) std::swap(t0, t1);
  for (double t : {t0, t1}) {
    float tf = float(t);
    if (!(tf > tNear && tf < tFar)) continue;
    double z = o.z + t * d.z;
    if (z < q.zMin || z > q.zMax) continue;
    if (!insidePhi(q, ox + t * dx, oy + t * dy)) continue;
    s = tf;
    return true;
  }
  return false;
}

}  // namespace

bool intersectQuadric(const Quadric& q, Vec3f o, Vec3f d, float tNear, float tFar, float& s) {
  return q.kind == Quadric::Kind::Disk ? diskHit(q, o, d, tNear, tFar, s) : cylinderHit(q, o, d, tNear, tFar, s);
}

Vec3f quadricNormal(const Quadric& q, Vec3f p) {
  if (q.kind == Quadric::Kind::Disk) return {0, 0, 1};
  float l = std::sqrt(p.x * p.x + p.y * p.y);
  return l > 0 ? Vec3f{p.x / l, p.y / l, 0} : Vec3f{1, 0, 0};
}

Bounds3f quadricBounds(const Quadric& q) {
  float r = q.radius;
  if (q.kind == Quadric::Kind::Disk) return {{-r, -r, q.height}, {r, r, q.height}};
  return {{-r, -r, q.zMin}, {r, r, q.zMax}};
}

float quadricArea(const Quadric& q) {
  if (q.kind == Quadric::Kind::Disk) return 0.5f * q.phiMax * (q.radius * q.radius - q.innerRadius * q.innerRadius);
  return q.phiMax * q.radius * (q.zMax - q.zMin);
}

}  // namespace tdpm
