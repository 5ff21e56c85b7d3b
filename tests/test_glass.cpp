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
#include "scene/bsdf.h"
#include "scene/light.h"
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
      o.method = RenderMethod::PathTrace;
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

// The eye path's first glass vertices are split (both branches, weighted by
// Fresnel) instead of choosing one: a highlight reflected on a glass ball is
// then in every sample that sees it. A lamp above a glass ball in a black
// world, seen reflected: in pixels whose whole area reflects onto the lamp
// each sample is F(theta) L_e (plus what the ball's inside adds), so 4
// samples give the analytic value and two seeds agree. Choosing by Fresnel
// (F ~ 5%) would give 0 or L_e per sample.
TEST_CASE("glass: the photon methods split the first glass vertex, so a reflected highlight is F L_e per sample") {
  auto d = test::emptyScene(48, 48);
  d.camera.position = {0, 2.2f, 3.2f};
  d.camera.target = {0, 0.3f, 0};
  d.camera.fovDegrees = 30;
  scene::MaterialDesc glass;
  glass.type = scene::MaterialDesc::Type::Dielectric;
  d.materials.push_back(glass);
  d.objects.push_back(test::sphere(1.0f, {0, 0, 0}, 0));
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Area;
  l.areaSize = {1.2f, 1.2f};
  l.placement.translate = {0, 3.0f, 0};
  l.power = Rgb(50.0f);
  d.lights.push_back(l);
  auto s = Scene::build(d);
  const Light& lamp = s->lights[0];
  AreaLightFrame lf = areaLightFrame(lamp, 0.5f);
  // Pixels whose four inset corners all see the ball and reflect onto the
  // lamp; the analytic value at the pixel centre.
  std::vector<std::pair<size_t, double>> highlight;
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 48; ++x) {
      bool all = true;
      double analytic = 0;
      for (Vec2f off : {Vec2f{0.5f, 0.5f}, Vec2f{0.1f, 0.1f}, Vec2f{0.9f, 0.1f}, Vec2f{0.1f, 0.9f}, Vec2f{0.9f, 0.9f}}) {
        Vec3f o, dir;
        s->camera.generateRay({x + off.x, y + off.y}, 0.5f, o, dir);
        Hit h;
        if (!s->intersect(o, dir, 1e30f, 0.5f, h) || h.isLight()) { all = false; break; }
        Vec3f n = normalize(h.n);
        float cosI = -dot(dir, n);
        Vec3f r = dir + n * (2.0f * cosI);
        Hit hl;
        if (!s->intersect(s->spawnOrigin(h.p, n, r), r, 1e30f, 0.5f, hl) || !hl.isLight()) { all = false; break; }
        if (off.x == 0.5f) analytic = fresnelDielectric(cosI, 1.5f) * areaLightRadiance(lamp, lf, hl.n, -r).average();
      }
      if (all) highlight.push_back({size_t(y) * 48 + size_t(x), analytic});
    }
  MESSAGE("highlight pixels: " << highlight.size());
  REQUIRE(highlight.size() >= 8);
  auto renderWith = [&](uint64_t seed) {
    RenderOptions o;
    o.method = RenderMethod::Standard;
    o.spp = 4;
    o.seed = seed;
    o.causticPhotons = 1000;
    o.globalPhotons = 1000;
    RenderStats st;
    return render(*s, o, Progress{}, st);
  };
  Film a = renderWith(1), b = renderWith(2);
  double ratio = 0, seedDiff = 0;
  for (auto [i, analytic] : highlight) {
    ratio += a.color[i].average() / analytic;
    seedDiff += std::fabs(a.color[i].average() - b.color[i].average()) / analytic;
  }
  ratio /= double(highlight.size());
  seedDiff /= double(highlight.size());
  MESSAGE("render / analytic " << ratio << ", mean |seed 1 - seed 2| / analytic " << seedDiff);
  // The ball's inside adds a little (light reflected inside and out again).
  CHECK(ratio == doctest::Approx(1.0).epsilon(0.05));
  CHECK(seedDiff < 0.05);
}
