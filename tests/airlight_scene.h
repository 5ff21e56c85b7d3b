// tests/airlight_scene.h — the airlight fixture of the media tests: a fog
// medium, Sun et al.'s single-scattering integral, the one-pixel scene it
// describes (camera ray along +z, a point light beside it, a black wall),
// and the mean and standard error of a value over seeded runs.
#pragma once
#include <cmath>
#include <vector>

#include "scene/description.h"
#include "scene_fixtures.h"

namespace tdpm::test {

inline scene::MediumDesc fog(Rgb sa, Rgb ss) {
  scene::MediumDesc m;
  m.name = "fog";
  m.sigmaA = sa;
  m.sigmaS = ss;
  return m;
}

// Sun et al. 2005: single scattering of an isotropic point light of
// intensity I at distance h from a ray, closest at ray parameter x0, along
// [0, D], medium (sigma_s, sigma_t), isotropic phase.
inline double airlight(double I, double sigmaS, double sigmaT, double x0, double h, double D) {
  double xi0 = M_PI / 4 + std::atan(-x0 / h) / 2, xi1 = M_PI / 4 + std::atan((D - x0) / h) / 2;
  const int n = 4000;
  double sum = 0;
  for (int i = 0; i < n; ++i) sum += std::exp(-sigmaT * h * std::tan(xi0 + (xi1 - xi0) * (i + 0.5) / n));
  return sigmaS * I * std::exp(-sigmaT * x0) / (2 * M_PI * h) * sum * (xi1 - xi0) / n;
}

// An isotropic point light of intensity I at `p`, inside medium `medium`.
inline scene::LightDesc pointLightIn(int medium, Vec3f p, float I) {
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Point;
  l.position = p;
  l.power = Rgb(4 * kPi * I);
  l.medium = medium;
  return l;
}

// Camera at the origin looking along +z, a black wall at z = D facing it,
// a point light at (h, 0, x0), fog everywhere.
inline scene::SceneDescription airlightScene(float I, float sa, float ss, float x0, float h, float D) {
  auto d = test::emptyScene(1, 1);
  d.camera.position = {0, 0, 0};
  d.camera.target = {0, 0, 1};
  d.camera.fovDegrees = 0.5f;
  d.materials.push_back(test::diffuse(Rgb(0.0f)));
  d.objects.push_back(test::box({100, 100, 0.01f}, {0, 0, D + 0.005f}, 0));
  d.media.push_back(fog(Rgb(sa), Rgb(ss)));
  d.exteriorMedium = d.camera.medium = 0;
  d.lights.push_back(pointLightIn(0, {h, 0, x0}, I));
  return d;
}

struct MeanError {
  double mean = 0, error = 0;
};
inline MeanError overRuns(const std::vector<double>& v) {
  MeanError m;
  for (double x : v) m.mean += x / double(v.size());
  double var = 0;
  for (double x : v) var += (x - m.mean) * (x - m.mean) / double(v.size() - 1);
  m.error = std::sqrt(var / double(v.size()));
  return m;
}

}  // namespace tdpm::test
