// tests/test_photon_render.cpp — the photon-map renderer against analytic
// answers and the path-traced reference: the moving plane (the effect the
// method exists for), a static scene paying nothing for time, adaptive
// sampling, and determinism across thread counts for every method.
#include <doctest/doctest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstring>
#include <memory>

#include "render/renderer.h"
#include "moving_plane.h"
#include "scene_fixtures.h"

using namespace tdpm;

namespace {

constexpr float kIntensity = test::kMovingPlaneIntensity;  // W/sr of the point light
constexpr float kRho = test::kMovingPlaneRho;

// A diffuse plane moving along its normal, from y = 0 down to y = -1 over
// the shutter [0, 1], under a point light at (0, 2, 0); camera above.
scene::SceneDescription movingPlane() { return test::movingPlaneScene(8); }

// Exact pixel mean: radiance rho/pi * I cos / d^2 of the plane point each
// sub-pixel ray meets at each time, averaged over a fine grid of both.
double analyticPixel(const Camera& cam, int x, int y) { return test::movingPlanePixel(cam, Shutter{0, 1}, x, y); }

RenderOptions photonOptions(const std::string& method) {
  RenderOptions o;
  o.method = *parseRenderMethod(method);
  o.spp = 16;
  o.seed = 11;
  o.causticPhotons = 0;
  o.globalPhotons = 400000;
  o.visualizeGlobal = true;
  o.estimate.k = 100;
  o.estimate.ks = 100;
  o.estimate.maxRadius = 1.0f;
  o.frames = 32;
  return o;
}

struct PlaneResult {
  double ratio;  // rendered / analytic, mean over the image
  RenderStats stats;
};

PlaneResult renderPlane(const std::string& method) {
  auto d = movingPlane();
  auto s = Scene::build(d);
  RenderOptions o = photonOptions(method);
  RenderStats st;
  Film f = render(*s, o, Progress{}, st);
  double got = 0, want = 0;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      got += f.color[f.index(x, y)].r;
      want += analyticPixel(s->camera, x, y);
    }
  return {got / want, st};
}

}  // namespace

TEST_CASE("moving plane: the time-dependent estimate matches the analytic irradiance") {
  PlaneResult r = renderPlane("time");
  MESSAGE("time / analytic = " << r.ratio);
  CHECK(r.ratio == doctest::Approx(1.0).epsilon(0.05));
  CHECK(r.stats.timeEstimates > 0);
  CHECK(r.stats.standardEstimates == 0);  // every eye ray meets the moving plane
}

TEST_CASE("moving plane: accumulation with many frames matches too") {
  PlaneResult r = renderPlane("accumulation");
  MESSAGE("accumulation / analytic = " << r.ratio);
  CHECK(r.ratio == doctest::Approx(1.0).epsilon(0.05));
}

TEST_CASE("moving plane: the standard estimate falls short by the factor the geometry predicts") {
  PlaneResult r = renderPlane("standard");
  // The k-NN ball of radius r around a point of the plane at time t holds
  // the photons of the times the plane was within r of it: a slice of
  // radius sqrt(r^2 - (v s)^2) at time offset s. With photons arriving at
  // N per unit area and time, k = N pi (4/3) r^3 / v, and the estimate
  // divides their energy by pi r^2 ts: it returns (4/3) r / (v ts) of the
  // truth. N at the centre: E / Q with Q = Phi ts / n_e (E ~ I / d^2 at
  // mid-shutter, d = 2.5).
  double v = 1.0, ts = 1.0;
  double E = kIntensity / (2.5 * 2.5);
  double Q = 4 * kPi * kIntensity * ts / double(r.stats.maps[MapKind::Global].emitted);
  double N = E / Q;
  double radius = std::cbrt(3.0 * 100 * v / (4 * kPi * N));
  double predicted = 4.0 / 3.0 * radius / (v * ts);
  MESSAGE("standard / analytic = " << r.ratio << ", predicted " << predicted << " (r = " << radius << ")");
  CHECK(r.ratio < 0.5);
  CHECK(r.ratio == doctest::Approx(predicted).epsilon(0.15));
}

namespace {

// A small lit scene with glass (so both maps fill), optionally with motion.
scene::SceneDescription smallCausticScene(bool moving) {
  auto d = test::emptyScene(32, 24);
  d.camera.position = {0, 2.0f, 3.5f};
  d.camera.target = {0, 0.3f, 0};
  d.materials.push_back(test::diffuse(Rgb(0.7f)));
  scene::MaterialDesc glass;
  glass.type = scene::MaterialDesc::Type::Dielectric;
  d.materials.push_back(glass);
  d.objects.push_back(test::quad({4, 4}, {0, 0, 0}, 0));
  d.objects.push_back(test::box({0.4f, 0.4f, 0.4f}, {-0.8f, 0.2f, 0}, 0));
  auto ball = test::sphere(0.35f, {0.2f, 0.8f, 0}, 1);
  if (moving) ball.motion = test::translation({-0.3f, 0, 0}, {0.3f, 0, 0});
  d.objects.push_back(ball);
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Point;
  l.position = {0.2f, 2.5f, 0};
  l.power = Rgb(150.0f);
  d.lights.push_back(l);
  return d;
}

Film renderWith(const scene::SceneDescription& d, RenderOptions o, RenderStats& st, int threads = 0) {
  auto s = Scene::build(d);
  std::unique_ptr<tbb::global_control> limit;
  if (threads > 0) limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
  return render(*s, o, Progress{}, st);
}

bool bitIdentical(const Film& a, const Film& b) {
  if (a.color.size() != b.color.size()) return false;
  return std::memcmp(a.color.data(), b.color.data(), a.color.size() * sizeof(Rgb)) == 0 &&
         std::memcmp(a.sampleCount.data(), b.sampleCount.data(), a.sampleCount.size() * sizeof(float)) == 0;
}

}  // namespace

TEST_CASE("static scene: time and standard give identical images and no temporal selection runs") {
  auto d = smallCausticScene(false);
  RenderOptions o;
  o.spp = 4;
  o.causticPhotons = 20000;
  o.globalPhotons = 5000;
  RenderStats stTime, stStd;
  o.method = RenderMethod::Time;
  Film a = renderWith(d, o, stTime);
  o.method = RenderMethod::Standard;
  Film b = renderWith(d, o, stStd);
  CHECK(bitIdentical(a, b));
  CHECK(stTime.timeEstimates == 0);
  CHECK(stTime.standardEstimates > 0);
  CHECK(stTime.maps[MapKind::Caustic].stored > 10000);  // the comparison is between lit images
  double sum = 0;
  for (Rgb c : a.color) sum += c.average();
  CHECK(sum > 0);
}

TEST_CASE("time method: only eye paths that can meet motion use the time-dependent estimate") {
  auto d = smallCausticScene(true);
  RenderOptions o;
  o.method = RenderMethod::Time;
  o.spp = 2;
  o.causticPhotons = 20000;
  o.globalPhotons = 5000;
  RenderStats st;
  renderWith(d, o, st);
  CHECK(st.timeEstimates > 0);
  CHECK(st.standardEstimates > st.timeEstimates);  // most of the image never meets the ball's swept bounds
}

TEST_CASE("adaptive sampling: pixels the moving object never crosses get the minimum, its path gets more") {
  // A black sphere crossing a white sky: sky pixels are exactly constant.
  // A pixel stops only when its 3x3 neighbourhood is converged and it has
  // kAdaptiveMinSamples (render/renderer.h), so sky pixels at least one
  // pixel away from the sphere's swept path take exactly that many.
  auto d = test::blackSphereAcrossSky(32, 8, 12, 0.5f, 1.5f);
  auto s = Scene::build(d);
  RenderOptions o;
  o.method = RenderMethod::PathTrace;
  o.spp = 16;
  o.maxSpp = 256;
  o.contrast = 0.02f;
  RenderStats st;
  Film f = render(*s, o, Progress{}, st);
  std::vector<uint8_t> touchedMap(size_t(f.width * f.height));
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      // Does the sphere's swept capsule cover any part of this pixel at any time?
      bool touched = false;
      for (int j = 0; j <= 4 && !touched; ++j)
        for (int i = 0; i <= 4 && !touched; ++i) {
          Vec3f ro, rd;
          s->camera.generateRay({x + i / 4.0f, y + j / 4.0f}, 0.5f, ro, rd);
          Vec3f p = ro + rd * ((0 - ro.z) / rd.z);
          float dx = std::max(0.0f, std::fabs(p.x) - 1.5f);
          touched = dx * dx + p.y * p.y <= 0.55f * 0.55f;
        }
      touchedMap[f.index(x, y)] = touched;
    }
  int crossed = 0, untouched = 0;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      bool near = false;
      for (int yy = std::max(0, y - 1); yy <= std::min(f.height - 1, y + 1); ++yy)
        for (int xx = std::max(0, x - 1); xx <= std::min(f.width - 1, x + 1); ++xx) near = near || touchedMap[f.index(xx, yy)];
      float n = f.sampleCount[f.index(x, y)];
      if (!near) {
        CHECK(n == float(kAdaptiveMinSamples));
        ++untouched;
      } else if (touchedMap[f.index(x, y)] && f.color[f.index(x, y)].r < 0.98f && f.color[f.index(x, y)].r > 0.02f) {
        CHECK(n > float(kAdaptiveMinSamples));
        ++crossed;
      }
    }
  CHECK(untouched > 50);
  CHECK(crossed > 20);
  CHECK(st.maxSpp > st.minSpp);
}

TEST_CASE("determinism: every method gives bit-identical images on 1 and 2 threads") {
  auto d = smallCausticScene(true);
  for (const char* method : {"pathtrace", "static", "accumulation", "standard", "time"}) {
    for (bool fourD : {false, true}) {
      if (fourD && std::string(method) != "time") continue;
      RenderOptions o;
      o.method = *parseRenderMethod(method);
      o.spp = 2;
      o.maxSpp = 8;
      o.causticPhotons = 8000;
      o.globalPhotons = 2000;
      o.frames = 3;
      o.spaceTime4D = fourD;
      RenderStats s1, s2;
      Film a = renderWith(d, o, s1, 1);
      Film b = renderWith(d, o, s2, 2);
      INFO(method << (fourD ? " (4d)" : ""));
      CHECK(bitIdentical(a, b));
      CHECK(s1.maps[MapKind::Caustic].stored == s2.maps[MapKind::Caustic].stored);
    }
  }
}
