// tests/test_reference_agreement.cpp — the photon methods against the
// unbiased path tracer on the paper's first case: a glass sphere focuses an
// area light onto a diffuse box that moves down through the focus. Inside
// the sphere's shadow the caustic is the only light, so the mean there
// compares the caustic itself: `time` and `accumulation` agree with the
// reference within 10%, `standard` loses much of it (method.md section 1).
#include <doctest/doctest.h>

#include <cmath>

#include "render/renderer.h"
#include "scene_fixtures.h"

using namespace tdpm;

namespace {

const Vec3f kLightCentre{0, 2.2f, 0};
const Vec3f kBallCentre{0, 1.2f, 0};
const float kBallRadius = 0.3f;

scene::SceneDescription causticBox() {
  auto d = test::emptyScene(48, 36);
  // Steep and far, so a pixel sees nearly the same part of the top face
  // while the box descends; the ball stays out of the line of sight.
  d.camera.position = {0, 5, 3};
  d.camera.target = {0, 0.45f, 0};
  d.camera.fovDegrees = 12;
  d.materials.push_back(test::diffuse(Rgb(0.8f)));
  scene::MaterialDesc glass;
  glass.type = scene::MaterialDesc::Type::Dielectric;
  d.materials.push_back(glass);
  d.objects.push_back(test::sphere(kBallRadius, kBallCentre, 1));
  auto box = test::box({0.8f, 0.2f, 0.8f}, {0, 0.5f, 0}, 0);  // top face from y = 0.6 ...
  box.motion = test::translation({0, 0, 0}, {0, -0.3f, 0});    // ... down to y = 0.3
  d.objects.push_back(box);
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Area;
  l.areaSize = {0.3f, 0.3f};
  l.placement.translate = kLightCentre;
  l.power = Rgb(30.0f);
  d.lights.push_back(l);
  return d;
}

// Pixels that see the box's top face at every time and, at mid-shutter, lie
// in the ball's shadow (the segment to the light's centre passes well inside
// the ball). Direct light elsewhere is computed alike by every method.
std::vector<size_t> shadowRegion(const Scene& s) {
  std::vector<size_t> region;
  for (int y = 0; y < s.camera.height(); ++y)
    for (int x = 0; x < s.camera.width(); ++x) {
      bool inside = true;
      for (float t : {0.0f, 0.5f, 1.0f}) {
        Vec3f o, d;
        s.camera.generateRay({x + 0.5f, y + 0.5f}, t, o, d);
        Hit h;
        if (!s.intersect(o, d, 1e30f, t, h) || h.object != 1 || h.n.y < 0.9f) { inside = false; break; }
        if (t != 0.5f) continue;
        Vec3f seg = kLightCentre - h.p;
        float along = dot(kBallCentre - h.p, seg) / lengthSquared(seg);
        float dist = length(h.p + seg * along - kBallCentre);
        if (dist > 0.6f * kBallRadius) { inside = false; break; }
      }
      if (inside) region.push_back(size_t(y) * size_t(s.camera.width()) + size_t(x));
    }
  return region;
}

double regionMean(const Film& f, const std::vector<size_t>& region) {
  double sum = 0;
  for (size_t i : region) sum += f.color[i].average();
  return sum / double(region.size());
}

double renderMean(const Scene& s, const std::vector<size_t>& region, const std::string& method, int spp) {
  RenderOptions o;
  o.method = *parseRenderMethod(method);
  o.spp = spp;
  o.seed = 21;
  o.causticPhotons = 300000;
  o.globalPhotons = 20000;
  o.frames = 16;
  o.estimate.k = 100;
  o.estimate.ks = 100;
  RenderStats st;
  return regionMean(render(s, o, Progress{}, st), region);
}

}  // namespace

TEST_CASE("reference: time and accumulation match the path-traced caustic on a moving box, standard does not") {
  auto d = causticBox();
  auto s = Scene::build(d);
  std::vector<size_t> region = shadowRegion(*s);
  MESSAGE("caustic region: " << region.size() << " pixels");
  REQUIRE(region.size() >= 20);
  double ref = renderMean(*s, region, "pathtrace", 2048);
  double time = renderMean(*s, region, "time", 16);
  double acc = renderMean(*s, region, "accumulation", 16);
  double standard = renderMean(*s, region, "standard", 16);
  MESSAGE("region mean: pathtrace " << ref << ", time " << time << " (" << time / ref << "), accumulation " << acc
                                    << " (" << acc / ref << "), standard " << standard << " (" << standard / ref << ")");
  REQUIRE(ref > 0);
  CHECK(time / ref == doctest::Approx(1.0).epsilon(0.10));
  CHECK(acc / ref == doctest::Approx(1.0).epsilon(0.10));
  CHECK(std::fabs(standard / ref - 1.0) > 0.10);
}
