// tests/test_mirror_laser.cpp — the second canonical case of method.md
// section 1: a laser (a narrow spot light) at the camera, reflected by a
// moving mirror onto the floor. Seen directly on the floor the spot is a
// streak whose length the motion predicts; seen in the mirror along the
// laser's own line of sight it stays a sharp spot with the time-dependent
// estimate, and is smeared with the standard one. Widths are measured in
// the image.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "render/renderer.h"
#include "scene_fixtures.h"

using namespace tdpm;

namespace {

const Vec3f kLaser{0, 3, 4};
const Vec3f kMirrorCentre{0, 1, 0};
const float kMirrorTilt = 93.58f;  // about x: the beam comes back down onto the floor near z = 1.5
const float kMirrorTravel = 0.3f;  // +-, along z
const float kConeDegrees = 1.0f;

scene::SceneDescription laserScene() {
  auto d = test::emptyScene(96, 96);
  d.camera.position = kLaser;
  d.camera.target = kMirrorCentre + Vec3f{0, -0.6f, 0.6f};
  d.camera.fovDegrees = 40;
  d.materials.push_back(test::diffuse(Rgb(0.8f)));
  scene::MaterialDesc mirror;
  mirror.type = scene::MaterialDesc::Type::Mirror;
  mirror.specular = Rgb(1.0f);
  d.materials.push_back(mirror);
  d.objects.push_back(test::quad({8, 8}, {0, 0, 0}, 0));
  auto m = test::quad({1.2f, 1.2f}, kMirrorCentre, 1);
  m.placement.rotate = Quaternion::fromAxisAngle({1, 0, 0}, kMirrorTilt * kPi / 180);
  m.motion = test::translation({0, 0, -kMirrorTravel}, {0, 0, kMirrorTravel});
  d.objects.push_back(m);
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Spot;
  l.position = kLaser;
  l.direction = normalize(kMirrorCentre - kLaser);
  l.coneAngle = kConeDegrees;
  l.falloffStart = 0.8f * kConeDegrees;
  l.power = Rgb(20.0f);
  d.lights.push_back(l);
  return d;
}

// Where the beam's axis lands on the floor at time t01 (geometry only).
Vec3f floorSpot(const Scene& s, float t01) {
  Affine3f m = s.objects[1].motion.atNormalized(t01);
  Vec3f c = m.point({0, 0, 0}), n = normalize(m.normal({0, 1, 0}));
  Vec3f d = normalize(kMirrorCentre - kLaser);
  float tm = dot(c - kLaser, n) / dot(d, n);
  Vec3f hit = kLaser + d * tm;
  Vec3f r = d - n * (2 * dot(d, n));
  float tf = -hit.y / r.y;
  return hit + r * tf;
}

struct Extent {
  int rows = 0, cols = 0, pixels = 0;
};

// Row and column extent of the pixels brighter than `fraction` of the
// brightest, among the pixels whose primary ray (at mid-shutter and at both
// ends) meets the mirror (`viaMirror`) or the floor directly.
Extent brightExtent(const Scene& s, const Film& f, bool viaMirror, float fraction) {
  std::vector<int> inRegion(f.color.size(), 0);
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      bool all = true;
      for (float t : {0.0f, 0.5f, 1.0f}) {
        Vec3f o, d;
        s.camera.generateRay({x + 0.5f, y + 0.5f}, t, o, d);
        Hit h;
        bool hit = s.intersect(o, d, 1e30f, t, h);
        all = all && hit && ((h.object == 1) == viaMirror);
      }
      inRegion[f.index(x, y)] = all;
    }
  float peak = 0;
  for (size_t i = 0; i < f.color.size(); ++i)
    if (inRegion[i]) peak = std::max(peak, f.color[i].luminance());
  int y0 = f.height, y1 = -1, x0 = f.width, x1 = -1;
  Extent e;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      size_t i = f.index(x, y);
      if (!inRegion[i] || f.color[i].luminance() < fraction * peak) continue;
      y0 = std::min(y0, y); y1 = std::max(y1, y);
      x0 = std::min(x0, x); x1 = std::max(x1, x);
      ++e.pixels;
    }
  e.rows = y1 >= y0 ? y1 - y0 + 1 : 0;
  e.cols = x1 >= x0 ? x1 - x0 + 1 : 0;
  return e;
}

Film renderLaser(const Scene& s, const std::string& method, float maxDt = -1) {
  RenderOptions o;
  o.method = *parseRenderMethod(method);
  o.spp = 16;
  o.seed = 5;
  o.causticPhotons = 100000;
  o.globalPhotons = 0;
  o.gatherRays = 0;
  o.estimate.k = 100;
  o.estimate.ks = 100;
  // Delta t_max: the renderer's default (10% of the shutter). Without it the
  // nearest-in-time estimate's k f / (2 dt) tails smear the spot: the
  // second case below checks that too.
  if (maxDt > 0) o.estimate.maxTimeDistance = maxDt;
  RenderStats st;
  return render(s, o, Progress{}, st);
}

}  // namespace

TEST_CASE("laser and moving mirror: a streak on the floor, a sharp spot in the mirror only with time") {
  auto d = laserScene();
  auto s = Scene::build(d);
  // Predicted streak: the beam's floor spot at the two shutter ends, in pixels.
  Vec2f a, b;
  REQUIRE(s->camera.project(floorSpot(*s, 0.0f), 0.0f, a));
  REQUIRE(s->camera.project(floorSpot(*s, 1.0f), 1.0f, b));
  float streakRows = std::fabs(a.y - b.y);
  // The spot seen in the mirror from the laser's own position subtends the
  // cone: 2 * cone / fov of the image height.
  float spotRows = 2 * kConeDegrees / 40.0f * float(d.camera.height);
  MESSAGE("predicted streak " << streakRows << " rows, spot " << spotRows << " rows");
  REQUIRE(streakRows > 3 * spotRows);  // the scene separates the two cases

  Film time = renderLaser(*s, "time");
  Film standard = renderLaser(*s, "standard");
  Extent floorTime = brightExtent(*s, time, false, 0.3f), floorStd = brightExtent(*s, standard, false, 0.3f);
  Extent mirrorTime = brightExtent(*s, time, true, 0.3f), mirrorStd = brightExtent(*s, standard, true, 0.3f);
  MESSAGE("floor streak rows: time " << floorTime.rows << ", standard " << floorStd.rows);
  MESSAGE("mirror spot rows: time " << mirrorTime.rows << ", standard " << mirrorStd.rows);
  // On the floor both show the streak, as long as the motion predicts.
  CHECK(floorTime.rows == doctest::Approx(streakRows).epsilon(0.35));
  CHECK(floorStd.rows == doctest::Approx(streakRows).epsilon(0.35));
  // In the mirror: a spot with time, a smear with standard.
  CHECK(mirrorTime.rows <= int(std::ceil(spotRows * 1.5f)) + 1);
  CHECK(mirrorStd.rows >= 2 * mirrorTime.rows);
  CHECK(mirrorTime.pixels > 0);
}

TEST_CASE("laser and moving mirror: without a time bound the nearest-in-time tails widen the spot") {
  auto d = laserScene();
  auto s = Scene::build(d);
  Film bounded = renderLaser(*s, "time");
  Film unbounded = renderLaser(*s, "time", 1e30f);
  Extent b = brightExtent(*s, bounded, true, 0.05f), u = brightExtent(*s, unbounded, true, 0.05f);
  MESSAGE("mirror spot pixels above 5% of the peak: bounded " << b.pixels << ", unbounded " << u.pixels);
  CHECK(u.pixels > b.pixels);
}
