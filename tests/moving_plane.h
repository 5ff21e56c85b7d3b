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

// The moving plane held still, and the only moving thing a speck above the
// light, in the camera's view (x and z within +-0.035 at y = 2.5), over 4
// frames at 4 fps (180 degrees): in every frame's shutter [i/4, i/4 + 1/8]
// it crosses a quarter of the view, from (-0.035, -0.035) to (0, 0) in x
// and z, and goes back while the shutter is closed. Every photon (light ->
// plane) is time-invariant; eye paths through the speck's swept bounds use
// the time-dependent estimate, the others the standard one. The plane's
// exact pixels: movingPlanePixel(cam, shutter, x, y, 0, 0, 1).
inline scene::SceneDescription stillPlaneUnderSpeck(int res) {
  auto d = movingPlaneScene(res);
  d.objects[0].motion = scene::MotionDesc{};
  auto speck = sphere(0.0005f, {0, 2.5f, 0}, 0);
  for (int i = 0; i <= 4; ++i)
    for (int half = 0; half < (i < 4 ? 2 : 1); ++half) {
      speck.motion.times.push_back(float(i) / 4.0f + float(half) / 8.0f);
      scene::TransformDesc pose;
      pose.translate = half ? Vec3f{0.0f, 0.0f, 0.0f} : Vec3f{-0.035f, 0.0f, -0.035f};
      speck.motion.poses.push_back(pose);
    }
  d.objects.push_back(speck);
  d.animation = scene::AnimationDesc{4.0, 4, 180.0};
  return d;
}

}  // namespace tdpm::test
