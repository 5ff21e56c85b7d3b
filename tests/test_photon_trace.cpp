// tests/test_photon_trace.cpp — photon tracing in time: energies
// (Q = flux ts / n_e) against analytic totals, projection-map emission
// against plain emission for every light type, time stratification.
#include <doctest/doctest.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "photon/tracer.h"
#include "scene_fixtures.h"

using namespace tdpm;

namespace {

double totalEnergy(const photon::PhotonStore& s) {
  double e = 0;
  for (size_t i = 0; i < s.size(); ++i) e += s.energy(i).average();
  return e;
}

scene::SceneDescription glassOverFloor(std::vector<scene::LightDesc> lights) {
  auto d = test::emptyScene(8, 8);
  d.camera.shutterClose = 2.0f;  // ts = 2 s: energies scale with it
  d.materials.push_back(test::diffuse(Rgb(0.5f)));
  scene::MaterialDesc glass;
  glass.type = scene::MaterialDesc::Type::Dielectric;
  d.materials.push_back(glass);
  d.objects.push_back(test::quad({20, 20}, {0, 0, 0}, 0));
  auto ball = test::sphere(0.4f, {0.3f, 1.0f, 0}, 1);
  ball.motion.times = {0.0f, 2.0f};
  ball.motion.poses.resize(2);
  ball.motion.poses[1].translate = {0.5f, 0, 0};
  d.objects.push_back(ball);
  d.lights = std::move(lights);
  return d;
}

}  // namespace

TEST_CASE("photon tracing: a point light over a floor stores its power times the shutter, times the hemisphere") {
  auto d = test::emptyScene(8, 8);
  d.camera.shutterClose = 2.0f;
  d.materials.push_back(test::diffuse(Rgb(0.5f)));
  d.objects.push_back(test::quad({2000, 2000}, {0, 0, 0}, 0));  // ~ the whole lower hemisphere
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Point;
  l.position = {0, 1, 0};
  l.power = Rgb(100.0f);
  d.lights.push_back(l);
  auto s = Scene::build(d);
  photon::TraceSettings ts;
  ts.kind = photon::MapKind::Global;
  ts.storedWanted = 50000;
  ts.maxBounces = 0;  // first hits only
  photon::TraceResult r = photon::tracePhotons(*s, ts, Progress{});
  CHECK(r.store.size() > 40000);
  // Half the power goes down; the floor (1000 m out at 1 m height) misses
  // a cone of half-angle atan(1000) around the horizon: ~0.05%.
  double expected = 100.0 * 2.0 * 0.5 * (1.0 - 1.0 / std::sqrt(1.0 + 1e6));
  CHECK(totalEnergy(r.store) == doctest::Approx(expected).epsilon(0.02));
}

TEST_CASE("photon tracing: projection maps keep the caustic energy and waste fewer paths, for every light type") {
  std::vector<scene::LightDesc> lights(4);
  lights[0].type = scene::LightDesc::Type::Point;
  lights[0].position = {0, 3, 0};
  lights[0].power = Rgb(100.0f);
  lights[1].type = scene::LightDesc::Type::Spot;
  lights[1].position = {0, 3, 0};
  lights[1].direction = {0, -1, 0};
  lights[1].coneAngle = 40;
  lights[1].falloffStart = 20;
  lights[1].power = Rgb(100.0f);
  lights[2].type = scene::LightDesc::Type::Directional;
  lights[2].direction = normalize(Vec3f{0.2f, -1, 0.1f});
  lights[2].power = Rgb(3.0f);
  lights[3].type = scene::LightDesc::Type::Area;
  lights[3].areaSize = {0.5f, 0.5f};
  lights[3].placement.translate = {0, 3, 0};
  lights[3].power = Rgb(100.0f);
  const char* names[] = {"point", "spot", "directional", "area"};
  // Paths saved at least this many times over: a 40-degree spot already
  // aims most of its power at the ball, the others waste most paths.
  const int minGain[] = {5, 2, 20, 2};
  for (int i = 0; i < 8; ++i) {
    if (i == 6) continue;  // sobol: the directional light's plain emission alone takes seconds
    auto d = glassOverFloor({lights[size_t(i % 4)]});
    auto s = Scene::build(d);
    photon::TraceSettings ts;
    ts.kind = photon::MapKind::Caustic;
    ts.storedWanted = 40000;
    ts.seed = 17;
    ts.sampler = i < 4 ? SamplerKind::Random : SamplerKind::Sobol;  // both kinds keep the energy
    photon::TraceResult with = photon::tracePhotons(*s, ts, Progress{});
    ts.projection = false;
    photon::TraceResult without = photon::tracePhotons(*s, ts, Progress{});
    double a = totalEnergy(with.store), b = totalEnergy(without.store);
    INFO(names[i % 4] << " (" << samplerName(ts.sampler) << "): with projection " << a << " J from " << with.emitted << " paths, without " << b << " J from "
                  << without.emitted);
    REQUIRE(b > 0);
    // Each total sums ~40k photons: a few per mille of noise; 3% bounds it.
    CHECK(a == doctest::Approx(b).epsilon(0.03));
    CHECK(with.emitted * uint64_t(minGain[i % 4]) < without.emitted);
  }
}

TEST_CASE("photon tracing: path times are stratified over the shutter and stored in their bins") {
  // A point light inside a closed (moving, so time is sampled) box: every
  // path stores exactly one photon, so the stored times are the path times.
  auto d = test::emptyScene(8, 8);
  d.camera.shutterOpen = 1.0f;
  d.camera.shutterClose = 3.0f;
  d.materials.push_back(test::diffuse(Rgb(0.5f)));
  auto box = test::box({2, 2, 2}, {0, 0, 0}, 0);
  box.motion.times = {1.0f, 3.0f};
  box.motion.poses.resize(2);
  box.motion.poses[1].translate = {0.01f, 0, 0};
  d.objects.push_back(box);
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Point;
  l.position = {0, 0, 0};
  d.lights.push_back(l);
  auto s = Scene::build(d);
  photon::TraceSettings ts;
  ts.kind = photon::MapKind::Global;
  ts.storedWanted = 25600;
  ts.maxBounces = 0;
  photon::TraceResult r = photon::tracePhotons(*s, ts, Progress{});
  REQUIRE(r.store.size() == r.emitted);
  std::vector<int> bins(256, 0);
  for (size_t i = 0; i < r.store.size(); ++i) bins[r.store.timeBin(i)]++;
  // A scrambled van der Corput sequence over a multiple of 256 paths puts
  // exactly the same number in every bin (random times: ~10% spread).
  REQUIRE(r.emitted % 256 == 0);
  int expected = int(r.emitted / 256);
  for (int b : bins) CHECK(b == expected);
  CHECK(r.store.t0() == 1.0f);
  CHECK(r.store.t1() == 3.0f);
}

TEST_CASE("photon tracing: several lights share the caustic map and keep its energy") {
  // A weak narrow spot and a strong area light both reach the ball: the
  // caustic map's light choice (half by power toward the targets, half
  // shared) must leave the total energy unchanged.
  scene::LightDesc spot;
  spot.type = scene::LightDesc::Type::Spot;
  spot.position = {0.3f, 3, 0};
  spot.direction = {0, -1, 0};
  spot.coneAngle = 2;
  spot.falloffStart = 1.5f;
  spot.power = Rgb(2.0f);
  scene::LightDesc area;
  area.type = scene::LightDesc::Type::Area;
  area.areaSize = {1, 1};
  area.placement.translate = {-1, 3, 0};
  area.power = Rgb(300.0f);
  auto d = glassOverFloor({spot, area});
  auto s = Scene::build(d);
  photon::TraceSettings ts;
  ts.kind = photon::MapKind::Caustic;
  ts.storedWanted = 60000;
  ts.seed = 4;
  photon::TraceResult with = photon::tracePhotons(*s, ts, Progress{});
  ts.projection = false;
  photon::TraceResult without = photon::tracePhotons(*s, ts, Progress{});
  double a = totalEnergy(with.store), b = totalEnergy(without.store);
  INFO("with projection " << a << " J, without " << b << " J");
  CHECK(a == doctest::Approx(b).epsilon(0.03));
}

TEST_CASE("photon tracing: a light inside a closed mirror sphere stops after a bounded pilot, with a warning") {
  // Every path bounces inside the mirror to the depth limit and stores
  // nothing. The pilot used to run 9.4M paths of ~17 rays per map (58 s for
  // a black 64x48 image); it now stops when a round would pass 1M paths or
  // 2M rays, and says how many paths it traced and what that bounds.
  auto d = test::emptyScene(8, 8);
  d.materials.push_back(test::diffuse(Rgb(0.5f)));
  scene::MaterialDesc mirror;
  mirror.type = scene::MaterialDesc::Type::Mirror;
  mirror.albedo.color = Rgb(0.95f);
  d.materials.push_back(mirror);
  d.objects.push_back(test::quad({10, 10}, {0, 0, 0}, 0));
  d.objects.push_back(test::sphere(0.8f, {0, 1, 0}, 1));
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Point;
  l.position = {0.1f, 1.05f, 0.02f};
  d.lights.push_back(l);
  auto s = Scene::build(d);
  for (photon::MapKind kind : {photon::MapKind::Caustic, photon::MapKind::Global}) {
    photon::TraceSettings ts;
    ts.kind = kind;
    ts.storedWanted = 100000;
    photon::TraceResult r = photon::tracePhotons(*s, ts, Progress{});
    INFO(r.warning);
    CHECK(r.store.size() == 0);
    CHECK(r.emitted == 0);
    CHECK(r.warning.find("none of") != std::string::npos);
    CHECK(r.warning.find("95% confidence") != std::string::npos);
    // Rounds of 16, 128 and then what fits the 2M-ray budget, each traced
    // from the start: at most 2^21 rays in the last round, 1/8 of that in
    // each earlier one, plus one batch's overshoot.
    CHECK(r.rays < (uint64_t(1) << 21) * 8 / 7 + 1024 * 17);
    CHECK(r.rays > (uint64_t(1) << 20));  // and it did look
  }
}

TEST_CASE("photon tracing: a narrow spot is emitted through its own cone, not the target's, with exact energies") {
  // Issue 10: a 1-degree spot aimed at a mirror emitted toward the mirror's
  // bounding sphere (16 degrees) and threw away 99.6% of its paths (51.2M
  // emitted, 181k stored). Now each target's sampling cone is the smaller of
  // the target's and the spot's (or nothing when they cannot meet); the
  // stored energy must still equal plain emission's.
  struct Case {
    const char* what;
    Vec3f aim;
    float cone;
    double minStoredPerPath;  // stored / emitted with projection
  };
  // The ball (radius 0.4, swept from x = 0.3 to 0.8 at y = 1) seen from
  // (0.3, 3, 0): its bounding sphere subtends ~17 degrees.
  const Case cases[] = {
      {"1-degree spot at the ball's centre", {0.55f, 1.0f, 0.0f}, 1.0f, 0.8},
      {"1-degree spot at the ball's rim", {0.9f, 1.0f, 0.0f}, 1.0f, 0.2},
      {"8-degree spot across the ball's edge", {1.0f, 1.0f, 0.0f}, 8.0f, 0.1},
  };
  for (const Case& c : cases) {
    scene::LightDesc spot;
    spot.type = scene::LightDesc::Type::Spot;
    spot.position = {0.3f, 3, 0};
    spot.direction = normalize(c.aim - spot.position);
    spot.coneAngle = c.cone;
    spot.falloffStart = 0.5f * c.cone;
    spot.power = Rgb(10.0f);
    auto d = glassOverFloor({spot});
    auto s = Scene::build(d);
    photon::TraceSettings ts;
    ts.kind = photon::MapKind::Caustic;
    ts.storedWanted = 40000;
    ts.seed = 23;
    photon::TraceResult with = photon::tracePhotons(*s, ts, Progress{});
    ts.projection = false;
    photon::TraceResult without = photon::tracePhotons(*s, ts, Progress{});
    double a = totalEnergy(with.store), b = totalEnergy(without.store);
    double rate = double(with.store.size()) / double(with.emitted);
    INFO(std::string(c.what) << ": with projection " << a << " J, " << with.store.size() << " stored of " << with.emitted
                << " paths; without " << b << " J, " << without.store.size() << " of " << without.emitted);
    REQUIRE(b > 0);
    CHECK(a == doctest::Approx(b).epsilon(0.03));
    CHECK(rate >= c.minStoredPerPath);
  }
  // A spot that cannot meet the ball stores nothing either way.
  scene::LightDesc away;
  away.type = scene::LightDesc::Type::Spot;
  away.position = {0.3f, 3, 0};
  away.direction = {0, 1, 0};
  away.coneAngle = 10;
  away.falloffStart = 10;
  auto s = Scene::build(glassOverFloor({away}));
  photon::TraceSettings ts;
  ts.kind = photon::MapKind::Caustic;
  ts.storedWanted = 1000;
  CHECK(photon::tracePhotons(*s, ts, Progress{}).store.size() == 0);
}

namespace {

// A point light at the centre of a diffuse sphere: every emitted path stores
// one photon at its emission direction times the radius.
std::unique_ptr<Scene> pointInSphere() {
  auto d = test::emptyScene(8, 8);
  d.camera.shutterClose = 2.0f;
  d.materials.push_back(test::diffuse(Rgb(0.5f)));
  d.objects.push_back(test::sphere(10.0f, {0, 0, 0}, 0));
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Point;
  l.position = {0, 0, 0};
  l.power = Rgb(100.0f);
  d.lights.push_back(l);
  return Scene::build(d);
}

photon::TraceResult firstHits(const Scene& s, SamplerKind kind, size_t wanted) {
  photon::TraceSettings ts;
  ts.kind = photon::MapKind::Global;
  ts.storedWanted = wanted;
  ts.maxBounces = 0;
  ts.seed = 7;
  ts.sampler = kind;
  return photon::tracePhotons(s, ts, Progress{});
}

// Chi-square of the photons' directions over 8 x 16 equal-solid-angle bins
// (cos theta in 8 equal slices, phi in 16).
double directionChiSquare(const photon::PhotonStore& st) {
  std::vector<double> bins(128, 0.0);
  for (size_t i = 0; i < st.size(); ++i) {
    Vec3f d = normalize(st.position(i));
    int zb = std::min(7, std::max(0, int((d.z + 1.0f) * 0.5f * 8.0f)));
    float phi = std::atan2(d.y, d.x) + float(M_PI);
    int pb = std::min(15, std::max(0, int(phi / float(2.0 * M_PI) * 16.0f)));
    bins[size_t(zb * 16 + pb)] += 1.0;
  }
  double expected = double(st.size()) / 128.0, chi = 0;
  for (double b : bins) chi += (b - expected) * (b - expected) / expected;
  return chi;
}

}  // namespace

TEST_CASE("photon tracing: sobol emission directions are better stratified than random, same energies") {
  auto s = pointInSphere();
  photon::TraceResult rnd = firstHits(*s, SamplerKind::Random, 16384);
  photon::TraceResult sob = firstHits(*s, SamplerKind::Sobol, 16384);
  REQUIRE(rnd.store.size() > 10000);
  REQUIRE(sob.store.size() > 10000);
  double chiR = directionChiSquare(rnd.store), chiS = directionChiSquare(sob.store);
  MESSAGE("chi-square over 128 bins: random " << chiR << ", sobol " << chiS);
  // Random: chi-square with 127 degrees of freedom (mean 127, sd ~16).
  CHECK(chiR > 70);
  CHECK(chiS < 0.25 * chiR);
  // The whole power reaches the sphere: 100 W * 2 s, exactly in expectation.
  CHECK(totalEnergy(rnd.store) == doctest::Approx(200.0).epsilon(0.01));
  CHECK(totalEnergy(sob.store) == doctest::Approx(200.0).epsilon(0.01));
}

TEST_CASE("photon tracing: a sobol map is identical for 1 and 2 threads") {
  auto s = pointInSphere();
  photon::TraceResult one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = firstHits(*s, SamplerKind::Sobol, 8000);
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = firstHits(*s, SamplerKind::Sobol, 8000);
  }
  REQUIRE(one.store.size() == two.store.size());
  REQUIRE(one.store.size() > 0);
  bool same = true;
  for (size_t i = 0; i < one.store.size(); ++i) {
    Vec3f a = one.store.position(i), b = two.store.position(i);
    same = same && a.x == b.x && a.y == b.y && a.z == b.z && one.store.time(i) == two.store.time(i);
  }
  CHECK(same);
  CHECK(one.emitted == two.emitted);
}
