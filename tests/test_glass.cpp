// tests/test_glass.cpp — the path tracer through a dielectric ball: a
// "furnace" (a glass ball under a uniform white sky, no lights) where every
// path must come back with weight exactly 1, since Fresnel reflection and
// refraction lose nothing and the 1/eta^2 radiance scaling of entering is
// undone on leaving. A self-intersection (a spawned ray re-hitting the
// surface it left) enters twice and returns 1/2.25; a roulette that judges
// the scaled weight inside the glass kills paths; either shows up here.
#include <doctest/doctest.h>

#include <cmath>

#include "render/renderer.h"
#include "scene_fixtures.h"

using namespace tdpm;

namespace {
scene::SceneDescription glassFurnace(bool moving, Vec3f centre) {
  auto d = test::emptyScene(32, 32);
  d.background = Rgb(1.0f);
  d.camera.position = centre + Vec3f{0, 0, 4};
  d.camera.target = centre;
  d.camera.fovDegrees = 30;  // the ball (r 0.8) fills most of the view, and its rim
  scene::MaterialDesc glass;
  glass.type = scene::MaterialDesc::Type::Dielectric;
  glass.ior = 1.5f;
  d.materials.push_back(glass);
  auto ball = test::sphere(0.8f, centre, 0);
  if (moving) ball.motion = test::translation({-0.3f, 0, 0}, {0.3f, 0, 0});  // offsets from the placement
  d.objects.push_back(ball);
  return d;
}
}  // namespace

TEST_CASE("glass: a dielectric ball under a white sky returns every path with weight 1") {
  // Far from the origin too: the spawn epsilon is relative to the position.
  for (Vec3f centre : {Vec3f{0, 2.2f, 0}, Vec3f{100, 102.2f, 100}})
    for (bool moving : {false, true}) {
      CAPTURE(centre.x);
      CAPTURE(moving);
      auto s = Scene::build(glassFurnace(moving, centre));
      RenderOptions o;
      o.method = "pathtrace";
      o.spp = o.maxSpp = 32;
      // Grazing rays reflect internally near the critical angle, with
      // Fresnel reflectance near 1, for many bounces: max depth 16 loses
      // about 1e-5 of the image (a few samples in 10^5); 1024 loses none.
      o.maxDepth = 1024;
      RenderStats st;
      Film f = render(*s, o, Progress{}, st);
      double mean = 0, worst = 0;
      for (const Rgb& c : f.color) {
        mean += c.g / double(f.color.size());
        worst = std::max(worst, std::fabs(double(c.g) - 1.0));
      }
      MESSAGE("centre x " << centre.x << (moving ? " moving" : " static") << ": mean " << mean << ", worst pixel off by " << worst);
      CHECK(worst < 1e-5);  // float rounding of 1/2.25 * 2.25 over a few interfaces
      o.maxDepth = 16;
      Film g = render(*s, o, Progress{}, st);
      double mean16 = 0;
      for (const Rgb& c : g.color) mean16 += c.g / double(g.color.size());
      CHECK(mean16 > 1.0 - 1e-4);
      // The ball is in view (glass under a white sky is invisible): made
      // black, it darkens the 44% of the view it covers.
      auto dark = glassFurnace(moving, centre);
      dark.materials[0] = test::diffuse(Rgb(0.0f));
      auto sd = Scene::build(dark);
      Film b = render(*sd, o, Progress{}, st);
      double meanDark = 0;
      for (const Rgb& c : b.color) meanDark += c.g / double(b.color.size());
      CHECK(meanDark < 0.7);  // the ball covers 44% of the view
    }
}
