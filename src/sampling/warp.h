// sampling/warp.h — maps from uniform [0,1)^n to the distributions the
// renderer and the photon tracer draw from, each with its density.
#pragma once
#include <algorithm>
#include <cmath>

#include "math/vec.h"

namespace tdpm {

// Shirley-Chiu concentric map: square -> unit disc, low distortion.
inline Vec2f squareToConcentricDisk(Vec2f u) {
  float a = 2.0f * u.x - 1.0f, b = 2.0f * u.y - 1.0f;
  if (a == 0 && b == 0) return {0, 0};
  float r, phi;
  if (std::fabs(a) > std::fabs(b)) { r = a; phi = (kPi / 4) * (b / a); }
  else { r = b; phi = (kPi / 2) - (kPi / 4) * (a / b); }
  return {r * std::cos(phi), r * std::sin(phi)};
}

// Cosine-weighted hemisphere around +z; pdf = cos(theta) / pi.
inline Vec3f squareToCosineHemisphere(Vec2f u) {
  Vec2f d = squareToConcentricDisk(u);
  float z = std::sqrt(std::max(0.0f, 1.0f - d.x * d.x - d.y * d.y));
  return {d.x, d.y, z};
}
inline float cosineHemispherePdf(float cosTheta) { return cosTheta > 0 ? cosTheta * kInvPi : 0.0f; }

// Uniform sphere; pdf = 1 / (4 pi).
inline Vec3f squareToUniformSphere(Vec2f u) {
  float z = 1.0f - 2.0f * u.x;
  float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  float phi = 2.0f * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
constexpr float kUniformSpherePdf = 1.0f / (4.0f * kPi);

// Uniform cone around +z with cos(half-angle) = cosMax; pdf = 1 / (2 pi (1 - cosMax)).
inline Vec3f squareToUniformCone(Vec2f u, float cosMax) {
  float cosT = 1.0f - u.x * (1.0f - cosMax);
  float sinT = std::sqrt(std::max(0.0f, 1.0f - cosT * cosT));
  float phi = 2.0f * kPi * u.y;
  return {sinT * std::cos(phi), sinT * std::sin(phi), cosT};
}
inline float uniformConePdf(float cosMax) { return 1.0f / (2.0f * kPi * (1.0f - cosMax)); }

// Veach's power heuristic (beta = 2) for two strategies with one sample each.
inline float powerHeuristic(float pdfA, float pdfB) {
  float a = pdfA * pdfA, b = pdfB * pdfB;
  return a + b > 0 ? a / (a + b) : 0.0f;
}

}  // namespace tdpm
