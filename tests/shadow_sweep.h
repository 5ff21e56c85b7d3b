// tests/shadow_sweep.h — the animation tests' scene where the only moving
// thing occludes part of a still light's photons: a still floor (albedo
// 0.5) lit by a still point light 3 m above it, and a thin slab at y = 1.5
// (0.5 x 0.05 x 0.5) crossing from x = -1.2 to 1.2 over the timeline [0, 1]
// s (4 frames at 4 fps, 180 degrees), whose shadow sweeps over the floor.
// Seen from above.
#pragma once
#include "scene/description.h"
#include "scene_fixtures.h"

namespace tdpm::test {

constexpr Vec3f kSweepLight{0, 3, 0};
constexpr float kSweepPower = 400.0f;

inline scene::SceneDescription shadowSweep(int res) {
  auto d = emptyScene(res, res);
  d.camera.position = {0, 5, 0};
  d.camera.target = {0, 0, 0};
  d.camera.up = {0, 0, -1};
  d.camera.fovDegrees = 40;
  d.materials.push_back(diffuse(Rgb(0.5f)));
  d.objects.push_back(quad({8, 8}, {0, 0, 0}, 0));
  auto slab = box({0.5f, 0.05f, 0.5f}, {0, 1.5f, 0}, 0);
  slab.motion = translation({-1.2f, 0, 0}, {1.2f, 0, 0});
  d.objects.push_back(slab);
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Point;
  l.position = kSweepLight;
  l.power = Rgb(kSweepPower);
  d.lights.push_back(l);
  d.animation = scene::AnimationDesc{4.0, 4, 180.0};
  return d;
}

}  // namespace tdpm::test
