// tests/moving_plane.h — the analytic moving plane several suites check the
// photon methods against: a diffuse plane (albedo kMovingPlaneRho) moving
// along its normal from y = 0 to y = -1 over the shutter [0, 1] (scene
// seconds), under a point light of kMovingPlaneIntensity W/sr at (0, 2, 0),
// seen by a camera above looking down, and its exact pixel values.
#pragma once
#include <cmath>

#include "math/vec.h"
#include "motion/shutter.h"
#include "render/render_options.h"
#include "scene/camera.h"
#include "scene_fixtures.h"

namespace tdpm::test {

constexpr float kMovingPlaneIntensity = 10.0f;  // W/sr of the point light
constexpr float kMovingPlaneRho = 0.5f;

inline scene::SceneDescription movingPlaneScene(int res) {
  auto d = emptyScene(res, res);
  d.camera.position = {0, 3, 0};
  d.camera.target = {0, 0, 0};
  d.camera.up = {0, 0, -1};
  d.camera.fovDegrees = 8;
  d.materials.push_back(diffuse(Rgb(kMovingPlaneRho)));
  auto plane = quad({6, 6}, {0, 0, 0}, 0);
  plane.motion = translation({0, 0, 0}, {0, -1, 0});
  d.objects.push_back(plane);
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Point;
  l.position = {0, 2, 0};
  l.power = Rgb(4 * kPi * kMovingPlaneIntensity);
  d.lights.push_back(l);
  return d;
}

// Exact mean of pixel (x, y) over scene times [t0, t1]: radiance
// rho/pi I cos / d^2 of the plane point (at y = -t) each sub-pixel ray
// meets at each time, averaged over a g x g x nt grid of both.
inline double movingPlanePixel(const Camera& cam, const Shutter& shutter, int x, int y, float t0 = 0.0f,
                               float t1 = 1.0f, int nt = 64) {
  const int g = 6;
  double sum = 0;
  for (int j = 0; j < g; ++j)
    for (int i = 0; i < g; ++i)
      for (int k = 0; k < nt; ++k) {
        float t = t0 + (t1 - t0) * (k + 0.5f) / nt;
        Vec3f o, dir;
        cam.generateRay({x + (i + 0.5f) / g, y + (j + 0.5f) / g}, shutter.normalized(t), o, dir);
        float s = (-t - o.y) / dir.y;
        Vec3f p = o + dir * s;
        Vec3f toL = Vec3f{0, 2, 0} - p;
        double d2 = lengthSquared(toL);
        sum += kMovingPlaneRho / kPi * kMovingPlaneIntensity * (toL.y / std::sqrt(d2)) / d2;
      }
  return sum / (g * g * nt);
}

// The `time` render of a moving-plane animation frame that test_animation
// and test_animation_progressive check: the global map seen directly (no
// caustic map, no gather), 100k photons per frame's shutter, k = k_s = 100.
inline RenderOptions movingPlaneFrameOptions(uint64_t seed) {
  RenderOptions o;
  o.method = RenderMethod::Time;
  o.spp = 16;
  o.seed = seed;
  o.causticPhotons = 0;
  o.globalPhotons = 100000;  // per frame's shutter time
  o.visualizeGlobal = true;
  o.estimate.k = 100;
  o.estimate.ks = 100;
  o.estimate.maxRadius = 1.0f;
  return o;
}

}  // namespace tdpm::test
