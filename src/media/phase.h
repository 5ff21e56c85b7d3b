// media/phase.h — the Henyey-Greenstein phase function, the one phase
// function of tdpm's media (pbrt-v4 and Mitsuba 0.6 default to it too).
// Directions follow the photon-map convention: wo points away from the
// scattering point towards the viewer, wi towards where light comes from;
// cosTheta = dot(wo, wi), so g > 0 (forward scattering) favours wi = -wo.
#pragma once
#include <cmath>

#include "math/frame.h"
#include "math/vec.h"

namespace tdpm::media {

constexpr float kInv4Pi = 0.07957747154594767f;

// p(cos) = (1 - g^2) / (4 pi (1 + g^2 + 2 g cos)^(3/2)), cos = dot(wo, wi);
// integrates to 1 over the sphere for every g in (-1, 1).
inline float henyeyGreenstein(float cosTheta, float g) {
  float denom = 1.0f + g * g + 2.0f * g * cosTheta;
  return kInv4Pi * (1.0f - g * g) / (denom * std::sqrt(std::fmax(denom, 1e-12f)));
}

// Samples wi with pdf henyeyGreenstein(dot(wo, wi), g) from u in [0, 1)^2
// (pbrt-v4's SampleHenyeyGreenstein, same convention). Returns the pdf,
// which is also the phase value (the sample's weight is exactly 1).
inline float sampleHenyeyGreenstein(Vec3f wo, float g, float u0, float u1, Vec3f& wi) {
  float cosTheta;
  if (std::fabs(g) < 1e-3f) {
    cosTheta = 1.0f - 2.0f * u0;
  } else {
    float sq = (1.0f - g * g) / (1.0f + g - 2.0f * g * u0);
    cosTheta = -(1.0f + g * g - sq * sq) / (2.0f * g);
  }
  // cosTheta is dot(wo, wi): p is largest at cos = -1 when g > 0.
  float sinTheta = std::sqrt(std::fmax(0.0f, 1.0f - cosTheta * cosTheta));
  float phi = 6.283185307179586f * u1;
  Frame f(wo);
  wi = f.toWorld(Vec3f(sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta));
  return henyeyGreenstein(cosTheta, g);
}

}  // namespace tdpm::media
