// tests/test_pathtrace.cpp — the reference path tracer against analytic
// answers: point/spot/area radiometry, furnace energy conservation, motion
// blur coverage of a moving sphere, a camera tracking an object, and
// bit-identical images for any thread count.
#include <doctest/doctest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstring>

#include "render/path_tracer.h"
#include "render/renderer.h"
#include "scene_fixtures.h"

using namespace tdpm;

namespace {

Film renderScene(const scene::SceneDescription& d, int spp, int maxDepth = 16, uint64_t seed = 7) {
  auto s = Scene::build(d);
  RenderOptions o;
  o.method = RenderMethod::PathTrace;
  o.spp = spp;
  o.maxDepth = maxDepth;
  o.seed = seed;
  RenderStats st;
  return render(*s, o, Progress{}, st);
}

// Radiance seen from `eye` toward point q, averaged over n paths.
Rgb meanRadiance(const Scene& s, Vec3f eye, Vec3f q, int n, uint64_t seed = 3, int maxDepth = 8) {
  PathTracer pt(s, maxDepth);
  Rng rng(seed);
  Rgb sum(0.0f);
  for (int i = 0; i < n; ++i) sum += pt.radiance(eye, normalize(q - eye), 0.5f, rng);
  return sum / float(n);
}

// Irradiance at the origin (normal +y) from a Lambertian polygon of radiance
// L facing it: E = L/2 * sum_i angle_i * (n . unit(v_i x v_i+1)) (Lambert's
// contour integral).
float polygonIrradiance(const std::vector<Vec3f>& verts, float L) {
  float sum = 0;
  for (size_t i = 0; i < verts.size(); ++i) {
    Vec3f a = normalize(verts[i]), b = normalize(verts[(i + 1) % verts.size()]);
    float angle = std::acos(std::clamp(dot(a, b), -1.0f, 1.0f));
    Vec3f c = cross(a, b);
    sum += angle * c.y / length(c);
  }
  return 0.5f * L * std::fabs(sum);
}

// A diffuse floor of albedo rho under one rectangular area light.
scene::SceneDescription floorUnderAreaLight(float rho, Vec2f size, Vec3f centre, float power) {
  auto d = test::emptyScene(4, 4);
  d.materials.push_back(test::diffuse(Rgb(rho)));
  d.objects.push_back(test::quad({40, 40}, {0, 0, 0}, 0));
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Area;
  l.areaSize = size;
  l.placement.translate = centre;
  l.power = Rgb(power);
  d.lights.push_back(l);
  return d;
}

}  // namespace

TEST_CASE("radiometry: diffuse plane under a point light is rho/pi * I cos / d^2") {
  auto d = test::emptyScene(4, 4);
  const float rho = 0.5f;
  d.materials.push_back(test::diffuse(Rgb(rho)));
  d.objects.push_back(test::quad({20, 20}, {0, 0, 0}, 0));
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Point;
  l.position = {0.3f, 2.0f, -0.2f};
  l.power = Rgb(4 * kPi * 10.0f, 4 * kPi * 5.0f, 4 * kPi * 2.0f);  // I = (10, 5, 2) W/sr
  d.lights.push_back(l);
  auto s = Scene::build(d);
  for (Vec3f q : {Vec3f{0, 0, 0}, Vec3f{1.5f, 0, 0.7f}, Vec3f{-3, 0, 2}, Vec3f{0.3f, 0, -0.2f}}) {
    Vec3f toL = l.position - q;
    float d2 = lengthSquared(toL);
    float cosT = toL.y / std::sqrt(d2);
    Rgb expected = Rgb(10, 5, 2) * (rho * kInvPi * cosT / d2);
    Rgb got = meanRadiance(*s, {q.x + 0.5f, 3.0f, q.z + 1.0f}, q, 4);
    for (int c = 0; c < 3; ++c) CHECK(got[c] == doctest::Approx(expected[c]).epsilon(0.01));
  }
}

TEST_CASE("radiometry: spot light is the point-light value inside the cone and zero outside") {
  auto d = test::emptyScene(4, 4);
  d.materials.push_back(test::diffuse(Rgb(0.8f)));
  d.objects.push_back(test::quad({40, 40}, {0, 0, 0}, 0));
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Spot;
  l.position = {0, 4, 0};
  l.direction = {0, -1, 0};
  l.coneAngle = 30;
  l.falloffStart = 20;
  l.power = Rgb(100.0f);
  d.lights.push_back(l);
  auto s = Scene::build(d);
  // I from the power: Phi = I 2 pi [(1 - cos 20) + (cos 20 - cos 30) / 5].
  float c20 = std::cos(20 * kPi / 180), c30 = std::cos(30 * kPi / 180);
  float I = 100.0f / (2 * kPi * ((1 - c20) + (c20 - c30) / 5));
  Vec3f inside{0.5f, 0, 0.3f};  // ~8 degrees off axis
  float d2 = lengthSquared(l.position - inside), cosT = 4.0f / std::sqrt(d2);
  Rgb got = meanRadiance(*s, {0.5f, 1, 2}, inside, 4);
  CHECK(got.r == doctest::Approx(0.8f * kInvPi * I * cosT / d2).epsilon(0.01));
  Vec3f outside{3.0f, 0, 0};  // ~37 degrees off axis
  CHECK(meanRadiance(*s, {3, 1, 2}, outside, 4).r == 0.0f);
}

TEST_CASE("radiometry: rectangular area light (NEE + MIS) matches Lambert's contour integral") {
  const float rho = 0.7f;
  auto s = Scene::build(floorUnderAreaLight(rho, {1.0f, 0.5f}, {0.4f, 1.0f, 0.2f}, 20.0f));
  float L = 20.0f / (kPi * 0.5f);  // radiance = power / (pi * area)
  std::vector<Vec3f> corners = {{-0.1f, 1, -0.05f}, {0.9f, 1, -0.05f}, {0.9f, 1, 0.45f}, {-0.1f, 1, 0.45f}};
  float E = polygonIrradiance(corners, L);
  Rgb got = meanRadiance(*s, {1.0f, 0.5f, 1.5f}, {0, 0, 0}, 40000);
  CHECK(got.r == doctest::Approx(rho * kInvPi * E).epsilon(0.01));
  // With one scattering vertex the light-sampled and BSDF-sampled halves of
  // the MIS pair must both be counted (the BSDF ray leaving the last vertex
  // is traced for emission): direct light alone is the whole answer here.
  Rgb direct = meanRadiance(*s, {1.0f, 0.5f, 1.5f}, {0, 0, 0}, 40000, 3, 1);
  MESSAGE("max depth 1: " << direct.r << ", expected " << rho * kInvPi * E);
  CHECK(direct.r == doctest::Approx(rho * kInvPi * E).epsilon(0.01));
}

TEST_CASE("furnace: white objects under a uniform sky reflect exactly the sky") {
  auto d = test::emptyScene(32, 32);
  d.background = Rgb(1.0f);
  d.camera.position = {0, 1.5f, 5};
  d.camera.target = {0, 0.5f, 0};
  d.materials.push_back(test::diffuse(Rgb(1.0f)));
  scene::MaterialDesc glass;
  glass.type = scene::MaterialDesc::Type::Dielectric;
  glass.ior = 1.5f;
  glass.specular = Rgb(1.0f);
  d.materials.push_back(glass);
  d.objects.push_back(test::quad({3, 3}, {0, 0, 0}, 0));
  d.objects.push_back(test::box({1, 1, 1}, {-0.7f, 0.5f, 0}, 0));
  d.objects.push_back(test::sphere(0.5f, {0.7f, 0.5f, 0}, 1));
  Film f = renderScene(d, 64, 64);
  double sum = 0;
  for (Rgb c : f.color) sum += c.average();
  double mean = sum / double(f.color.size());
  CHECK(mean == doctest::Approx(1.0).epsilon(0.01));
}

TEST_CASE("furnace: a convex diffuse sphere of albedo rho under a uniform sky has radiance rho") {
  auto d = test::emptyScene(16, 16);
  d.background = Rgb(1.0f);
  d.camera.position = {0, 0, 3};
  d.camera.target = {0, 0, 0};
  d.camera.fovDegrees = 20;  // the sphere covers the central pixels
  d.materials.push_back(test::diffuse(Rgb(0.5f, 0.25f, 0.75f)));
  d.objects.push_back(test::sphere(0.5f, {0, 0, 0}, 0));
  Film f = renderScene(d, 256);
  Rgb sum(0.0f);
  int n = 0;
  for (int y = 6; y < 10; ++y)
    for (int x = 6; x < 10; ++x) { sum += f.color[f.index(x, y)]; ++n; }
  Rgb mean = sum / float(n);
  CHECK(mean.r == doctest::Approx(0.5f).epsilon(0.01));
  CHECK(mean.g == doctest::Approx(0.25f).epsilon(0.01));
  CHECK(mean.b == doctest::Approx(0.75f).epsilon(0.01));
}

namespace {

// Fraction of the shutter [0,1] during which the ray o + s d (d unit) passes
// within r of the centre c0 + v t: |perp(c0 - o) + perp(v) t|^2 <= r^2.
double coveredFraction(Vec3f o, Vec3f d, Vec3f c0, Vec3f v, float r) {
  auto perp = [&](Vec3f w) { return w - d * dot(w, d); };
  Vec3f a = perp(c0 - o), b = perp(v);
  double A = dot(b, b), B = 2.0 * dot(a, b), C = double(dot(a, a)) - double(r) * r;
  if (A == 0) return C <= 0 ? 1.0 : 0.0;
  double disc = B * B - 4 * A * C;
  if (disc <= 0) return 0.0;
  double s = std::sqrt(disc);
  double t0 = (-B - s) / (2 * A), t1 = (-B + s) / (2 * A);
  return std::max(0.0, std::min(1.0, t1) - std::max(0.0, t0));
}

}  // namespace

TEST_CASE("motion blur: a black sphere crossing a white sky covers each pixel for the predicted fraction") {
  auto d = test::blackSphereAcrossSky(24, 6, 10, 0.25f, 2.5f);
  Vec3f from{-2.5f, 0, 0}, to{2.5f, 0, 0};
  Film f = renderScene(d, 256);
  Camera cam(d.camera);
  int checked = 0;
  for (int y = 0; y < d.camera.height; ++y)
    for (int x = 0; x < d.camera.width; ++x) {
      // Expected pixel value: 1 - covered fraction, averaged over a fine
      // sub-pixel grid with the exact per-ray time interval.
      const int g = 12;
      double cover = 0;
      for (int j = 0; j < g; ++j)
        for (int i = 0; i < g; ++i) {
          Vec3f ro, rd;
          cam.generateRay({x + (i + 0.5f) / g, y + (j + 0.5f) / g}, 0.5f, ro, rd);
          cover += coveredFraction(ro, rd, from, to - from, 0.25f);
        }
      double expected = 1.0 - cover / (g * g);
      size_t idx = f.index(x, y);
      double sigma = std::sqrt(double(f.varianceOfMean[idx].r));
      CHECK(std::fabs(f.color[idx].r - expected) <= 5 * sigma + 0.01);
      if (expected < 0.99) ++checked;
    }
  CHECK(checked >= 24);  // the whole path across the image was tested
}

TEST_CASE("moving camera: a camera moving with an object sees it exactly as if both stood still") {
  auto d = test::emptyScene(24, 24);
  d.background = Rgb(1.0f);
  d.camera.position = {0, 0, 4};
  d.camera.target = {0, 0, 0};
  d.camera.fovDegrees = 30;
  d.materials.push_back(test::diffuse(Rgb(0.0f)));
  d.objects.push_back(test::sphere(0.5f, {0, 0, 0}, 0));
  Film still = renderScene(d, 16);

  auto m = d;
  Vec3f shift{3, 0.5f, 0};
  m.objects[0].motion = test::translation({0, 0, 0}, shift);
  m.camera.motion = {{0.0f, {0, 0, 4}, {0, 0, 0}, {0, 1, 0}}, {1.0f, Vec3f{0, 0, 4} + shift, shift, {0, 1, 0}}};
  Film tracked = renderScene(m, 16);
  double diff = 0;
  for (size_t i = 0; i < still.color.size(); ++i) diff += std::fabs(still.color[i].r - tracked.color[i].r);
  CHECK(diff / double(still.color.size()) < 1e-3);

  // And a static camera sees the same motion blurred: the images differ.
  auto blurred = m;
  blurred.camera.motion.clear();
  Film b = renderScene(blurred, 16);
  double diffB = 0;
  for (size_t i = 0; i < still.color.size(); ++i) diffB += std::fabs(still.color[i].r - b.color[i].r);
  CHECK(diffB / double(still.color.size()) > 0.05);
}

TEST_CASE("determinism: 1 and 2 threads give bit-identical images") {
  auto d = test::emptyScene(40, 30);
  d.camera.position = {0, 1.5f, 4};
  d.camera.target = {0, 0.3f, 0};
  d.materials.push_back(test::diffuse(Rgb(0.7f)));
  scene::MaterialDesc glass;
  glass.type = scene::MaterialDesc::Type::Dielectric;
  d.materials.push_back(glass);
  d.objects.push_back(test::quad({6, 6}, {0, 0, 0}, 0));
  auto ball = test::sphere(0.4f, {0, 0.5f, 0}, 1);
  ball.motion = test::translation({-0.5f, 0, 0}, {0.5f, 0.3f, 0});
  d.objects.push_back(ball);
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Area;
  l.placement.translate = {0, 2.5f, 0};
  l.power = Rgb(50.0f);
  d.lights.push_back(l);
  Film one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = renderScene(d, 8);
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = renderScene(d, 8);
  }
  bool identical = true;
  for (size_t i = 0; i < one.color.size(); ++i)
    for (int c = 0; c < 3; ++c) identical &= (std::memcmp(&one.color[i][c], &two.color[i][c], sizeof(float)) == 0);
  CHECK(identical);
  double sum = 0;
  for (Rgb c : one.color) sum += c.average();
  CHECK(sum > 0);  // the scene is lit: the comparison is not between two black images
}

TEST_CASE("radiometry: a moving point light gives the time average of rho/pi * I cos / d^2") {
  auto d = test::emptyScene(4, 4);
  const float rho = 0.6f, I = 8.0f;
  d.materials.push_back(test::diffuse(Rgb(rho)));
  d.objects.push_back(test::quad({40, 40}, {0, 0, 0}, 0));
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Point;
  l.position = {0, 1.5f, 0};
  l.power = Rgb(4 * kPi * I);
  l.motion = test::translation({-2, 0, 0}, {2, 0, 0});
  d.lights.push_back(l);
  auto s = Scene::build(d);
  REQUIRE(s->hasMotion);
  Vec3f q{0.5f, 0, 0.25f};
  // Exact time average by a fine midpoint rule over the shutter.
  double expected = 0;
  const int nt = 4000;
  for (int k = 0; k < nt; ++k) {
    float t = (k + 0.5f) / nt;
    Vec3f lp{-2 + 4 * t, 1.5f, 0};
    Vec3f toL = lp - q;
    double d2 = lengthSquared(toL);
    expected += rho / kPi * I * (toL.y / std::sqrt(d2)) / d2;
  }
  expected /= nt;
  // The path tracer at stratified times (one per path, as the renderer does).
  PathTracer pt(*s, 4);
  Rng rng(5);
  Vec3f eye{0.5f, 2.0f, 1.0f};
  const int n = 4096;
  double sum = 0;
  for (int i = 0; i < n; ++i) sum += pt.radiance(eye, normalize(q - eye), (i + rng.uniform()) / n, rng).r;
  CHECK(sum / n == doctest::Approx(expected).epsilon(0.01));
}

TEST_CASE("radiometry: a moving area light (geometry and light sampling move together) matches the contour integral") {
  const float rho = 0.7f;
  auto d = floorUnderAreaLight(rho, {0.8f, 0.4f}, {0, 0.8f, 0}, 12.0f);
  d.lights[0].motion = test::translation({-0.6f, 0, 0}, {0.6f, 0, 0});
  auto s = Scene::build(d);
  float L = 12.0f / (kPi * 0.32f);
  double expected = 0;
  const int nt = 400;
  for (int k = 0; k < nt; ++k) {
    float cx = -0.6f + 1.2f * (k + 0.5f) / nt;
    std::vector<Vec3f> c = {{cx - 0.4f, 0.8f, -0.2f}, {cx + 0.4f, 0.8f, -0.2f}, {cx + 0.4f, 0.8f, 0.2f}, {cx - 0.4f, 0.8f, 0.2f}};
    expected += rho * kInvPi * polygonIrradiance(c, L);
  }
  expected /= nt;
  PathTracer pt(*s, 4);
  Rng rng(6);
  Vec3f eye{0.8f, 0.4f, 1.5f};
  const int n = 60000;
  double sum = 0;
  for (int i = 0; i < n; ++i) sum += pt.radiance(eye, normalize(Vec3f{0, 0, 0} - eye), (i + rng.uniform()) / n, rng).r;
  CHECK(sum / n == doctest::Approx(expected).epsilon(0.01));
}
