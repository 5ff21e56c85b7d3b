// tests/test_media_photons.cpp — photon tracing through participating media
// (photon/tracer_media.h) and the volume photon map (issue 25, photon side):
// the stored energies of single scattering against the closed form in an
// infinite medium (per shell, grey and chromatic), the total against the
// expected number of scattering events (infinite absorbing medium: a
// geometric series; a non-absorbing ball: an independent random walk),
// surface photons through a slab of fog against exp(-sigma_t L), the beam
// map built for the volume kind, and the volume kind left out of a scene
// without media. Fixed seeds; bounds are 4 standard errors.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "cli_harness.h"
#include "core/rng.h"
#include "photon/tracer.h"
#include "image/exr.h"
#include "render/photon_map.h"
#include "render/progressive.h"
#include "render/progressive_io.h"
#include "scene/scene.h"
#include "scene_fixtures.h"

using namespace tdpm;

namespace {

scene::MediumDesc homogeneous(Rgb sa, Rgb ss, float g = 0.0f) {
  scene::MediumDesc m;
  m.sigmaA = sa;
  m.sigmaS = ss;
  m.g = g;
  return m;
}

// A point light of power P at the origin inside fog everywhere (exterior
// medium 0), no objects.
scene::SceneDescription pointInFog(Rgb sa, Rgb ss, Rgb power) {
  auto d = test::emptyScene(4, 4);
  d.media.push_back(homogeneous(sa, ss));
  d.exteriorMedium = d.camera.medium = 0;
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Point;
  l.position = {0, 0, 0};
  l.power = power;
  l.medium = 0;
  d.lights.push_back(l);
  return d;
}

photon::TraceSettings volumeTrace(size_t wanted, int maxBounces, uint64_t seed = 5) {
  photon::TraceSettings ts;
  ts.kind = MapKind::Volume;
  ts.storedWanted = wanted;
  ts.maxBounces = maxBounces;
  ts.seed = seed;
  return ts;
}

// Sum of one channel of the energies of the photons with |x| in [r0, r1),
// and the standard error of that sum (each path stores at most one photon
// there when only first scatterings are kept: sqrt(sum e^2) bounds it).
struct Sum {
  double value = 0, error = 0;
  size_t count = 0;
};
Sum shellSum(const photon::PhotonStore& s, float r0, float r1, int channel) {
  Sum out;
  double e2 = 0;
  for (size_t i = 0; i < s.size(); ++i) {
    float r = length(s.position(i));
    if (r < r0 || r >= r1) continue;
    Rgb e = s.energy(i);
    double v = channel == 0 ? e.r : channel == 1 ? e.g : e.b;
    out.value += v;
    e2 += v * v;
    ++out.count;
  }
  out.error = std::sqrt(e2);
  return out;
}

double channel(Rgb c, int k) { return k == 0 ? c.r : k == 1 ? c.g : c.b; }

}  // namespace

TEST_CASE("media photons: single scattering around a point light matches sigma_s P e^(-sigma_t d) / (4 pi d^2)") {
  // maxBounces 0: a path stores its first scattering event and ends, so the
  // stored energy per unit volume at distance d is the single-scattering
  // density sigma_s P ts e^(-sigma_t d) / (4 pi d^2); over the shell
  // [d0, d1) it integrates to P ts sigma_s / sigma_t (e^(-sigma_t d0) -
  // e^(-sigma_t d1)). Grey (plain exponential flights) and chromatic
  // (spectral tracking: per-channel weights, unbiased per channel).
  struct Case {
    Rgb sa, ss;
  };
  const Case cases[] = {{Rgb(0.2f), Rgb(0.6f)}, {Rgb(0.1f, 0.3f, 0.05f), Rgb(0.4f, 0.9f, 1.6f)}};
  const Rgb P(30.0f, 20.0f, 10.0f);
  for (SamplerKind sampler : {SamplerKind::Random, SamplerKind::Sobol})
  for (const Case& c : cases) {
    auto s = Scene::build(pointInFog(c.sa, c.ss, P));
    REQUIRE(s->hasMedia());
    photon::TraceSettings settings = volumeTrace(60000, 0);
    settings.sampler = sampler;
    photon::TraceResult r = photon::tracePhotons(*s, settings, Progress{});
    REQUIRE(r.emitted > 0);
    const double ts = 1.0;  // shutter [0, 1]
    const float shells[] = {0.0f, 0.3f, 1.0f, 2.0f, 4.0f};
    for (int k = 0; k < 3; ++k) {
      const double st = channel(c.sa, k) + channel(c.ss, k), ss = channel(c.ss, k);
      for (int j = 0; j + 1 < 5; ++j) {
        Sum got = shellSum(r.store, shells[j], shells[j + 1], k);
        double want = channel(P, k) * ts * ss / st * (std::exp(-st * shells[j]) - std::exp(-st * shells[j + 1]));
        INFO("sigma_s " << ss << " sigma_t " << st << " channel " << k << " shell [" << shells[j] << ", "
                        << shells[j + 1] << "): " << got.value << " J from " << got.count << " photons, want " << want
                        << " (error " << got.error << ")");
        CHECK(std::fabs(got.value - want) < 4.0 * got.error + 1e-9);
        CHECK(got.count > 100);
      }
    }
    // The photons carry the path's time (spread over the shutter) and the
    // direction they came from: from the light, so -wi points away from it.
    double outward = 0;
    for (size_t i = 0; i < std::min<size_t>(r.store.size(), 2000); ++i)
      outward += dot(normalize(r.store.position(i)), r.store.direction(i)) < -0.99f;
    CHECK(outward == 2000);
  }
}

TEST_CASE("media photons: every scattering event is stored, as many as the expected number of events") {
  // An infinite medium with albedo a: every collision scatters with
  // probability a, so a path scatters N times with E[N] = a / (1 - a), and
  // the stored energies sum to P ts a / (1 - a) (deep enough bounces that
  // the cut-off, a^65, does not matter). Grey: every photon carries P ts / n.
  const float sa = 0.5f, ss = 1.5f;  // a = 0.75: E[N] = 3
  auto s = Scene::build(pointInFog(Rgb(sa), Rgb(ss), Rgb(12.0f)));
  photon::TraceResult r = photon::tracePhotons(*s, volumeTrace(90000, 64), Progress{});
  REQUIRE(r.emitted > 0);
  double sum = 0;
  for (size_t i = 0; i < r.store.size(); ++i) sum += r.store.energy(i).g;
  const double a = ss / (sa + ss), perPath = a / (1 - a);
  const double want = 12.0 * perPath;
  // N is geometric with variance a / (1 - a)^2 per path.
  const double error = 12.0 * std::sqrt(a / ((1 - a) * (1 - a)) / double(r.emitted));
  INFO(sum << " J stored from " << r.emitted << " paths, want " << want << " +- " << error);
  CHECK(std::fabs(sum - want) < 4.0 * error);
  // And with albedo 1/4 the sum falls to a / (1 - a) = 1/3 of P ts.
  auto s2 = Scene::build(pointInFog(Rgb(1.5f), Rgb(0.5f), Rgb(12.0f)));
  photon::TraceResult r2 = photon::tracePhotons(*s2, volumeTrace(30000, 64), Progress{});
  double sum2 = 0;
  for (size_t i = 0; i < r2.store.size(); ++i) sum2 += r2.store.energy(i).g;
  const double a2 = 0.25, error2 = 12.0 * std::sqrt(a2 / ((1 - a2) * (1 - a2)) / double(r2.emitted));
  CHECK(std::fabs(sum2 - 12.0 * a2 / (1 - a2)) < 4.0 * error2);
}

TEST_CASE("media photons: volume furnace: a non-absorbing ball around a point light stores P ts E[N]") {
  // A ball of radius R of a non-absorbing medium (interface boundary,
  // vacuum outside) with the light at its centre: a path scatters until it
  // leaves the ball, and the volume map's energies sum to P ts E[N]. E[N]
  // is counted by an independent isotropic random walk in the test (no
  // scene, no tracer), within both runs' errors. Chromatic sigma_s: the
  // per-channel spectral-tracking weights keep each channel's sum right.
  const float R = 1.0f;
  const Rgb sigmaS(1.0f, 2.0f, 3.0f);
  auto d = pointInFog(Rgb(0.0f), sigmaS, Rgb(5.0f));
  d.exteriorMedium = d.camera.medium = -1;
  scene::MaterialDesc none;
  none.type = scene::MaterialDesc::Type::Interface;
  d.materials.push_back(none);
  auto ball = test::sphere(R, {0, 0, 0}, 0);
  ball.media.present = true;
  ball.media.inside = 0;
  ball.media.outside = -1;
  d.objects.push_back(ball);
  auto s = Scene::build(d);
  photon::TraceResult r = photon::tracePhotons(*s, volumeTrace(150000, 200), Progress{});
  REQUIRE(r.emitted > 0);
  Rgb sum(0.0f);
  double sum2[3] = {0, 0, 0};
  for (size_t i = 0; i < r.store.size(); ++i) sum += r.store.energy(i);
  for (int k = 0; k < 3; ++k) {
    // The independent walk: exponential steps of rate sigma_s, isotropic
    // directions, count the collisions inside the ball.
    const double sig = channel(sigmaS, k);
    Rng rng(77 + uint64_t(k), 3);
    const int walks = 200000;
    double n1 = 0, n2 = 0;
    for (int w = 0; w < walks; ++w) {
      double x = 0, y = 0, z = 0;
      int n = 0;
      for (;;) {
        double u = rng.uniform(), v = rng.uniform();
        double cz = 1 - 2 * u, sz = std::sqrt(std::max(0.0, 1 - cz * cz)), ph = 2 * kPi * v;
        double step = -std::log(1.0 - double(rng.uniform())) / sig;
        x += step * sz * std::cos(ph);
        y += step * sz * std::sin(ph);
        z += step * cz;
        if (x * x + y * y + z * z >= double(R) * R) break;
        ++n;
      }
      n1 += n;
      n2 += double(n) * n;
    }
    const double mean = n1 / walks, var = n2 / walks - mean * mean;
    const double want = 5.0 * mean;
    // The tracer's sum: per path N_i times P ts / n (grey) or its weights;
    // its error from the walk's variance (the same process).
    const double err = 5.0 * std::sqrt(var / double(r.emitted) + var / walks);
    (void)sum2;
    INFO("channel " << k << ": " << channel(sum, k) << " J stored, want " << want << " (E[N] " << mean << ") +- " << err);
    CHECK(std::fabs(channel(sum, k) - want) < 4.0 * err + 0.01 * want);
  }
}

TEST_CASE("media photons: surface photons through a slab of fog arrive attenuated by exp(-sigma_t L)") {
  // A sun straight down on a floor through a fog slab of thickness L: the
  // direct photons (max bounces 0: a scattering event ends the path) reach
  // the floor with probability exp(-sigma_t L); without the fog the floor's
  // global photons sum to E A ts.
  auto make = [](bool fog) {
    auto d = test::emptyScene(4, 4);
    d.materials.push_back(test::diffuse(Rgb(0.5f)));
    scene::MaterialDesc none;
    none.type = scene::MaterialDesc::Type::Interface;
    d.materials.push_back(none);
    d.objects.push_back(test::quad({4, 4}, {0, 0, 0}, 0));
    if (fog) {  // (an interface without media is a delta surface to the plain tracer: no slab then)
      auto slab = test::box({20, 1, 20}, {0, 1.0f, 0}, 1);  // y in [0.5, 1.5]
      d.media.push_back(homogeneous(Rgb(0.3f, 0.5f, 0.1f), Rgb(0.4f, 0.6f, 0.2f)));
      slab.media.present = true;
      slab.media.inside = 0;
      slab.media.outside = -1;
      d.objects.push_back(slab);
    }
    scene::LightDesc sun;
    sun.type = scene::LightDesc::Type::Directional;
    sun.direction = {0, -1, 0};
    sun.power = Rgb(2.0f);
    d.lights.push_back(sun);
    return d;
  };
  photon::TraceSettings ts;
  ts.kind = MapKind::Global;
  ts.storedWanted = 40000;
  ts.maxBounces = 0;
  ts.seed = 9;
  auto clear = Scene::build(make(false));
  auto foggy = Scene::build(make(true));
  REQUIRE(!clear->hasMedia());
  REQUIRE(foggy->hasMedia());
  photon::TraceResult a = photon::tracePhotons(*clear, ts, Progress{});
  photon::TraceResult b = photon::tracePhotons(*foggy, ts, Progress{});
  auto total = [](const photon::PhotonStore& st) {
    Rgb e(0.0f);
    for (size_t i = 0; i < st.size(); ++i) e += st.energy(i);
    return e;
  };
  const Rgb ea = total(a.store), eb = total(b.store);
  const double area = 16.0, E = 2.0;  // the floor's 4 x 4 under 2 W/m^2
  CHECK(ea.g == doctest::Approx(E * area).epsilon(4.0 / std::sqrt(double(a.store.size()))));
  const Rgb st(0.7f, 1.1f, 0.3f);
  for (int k = 0; k < 3; ++k) {
    const double T = std::exp(-channel(st, k)), want = E * area * T;
    // Photons reach the floor with a probability proportional to T (the
    // grey-majorant flights with spectral weights): binomial-like error.
    const double n = double(b.store.size());
    INFO("channel " << k << ": " << channel(eb, k) << " J through the fog, want " << want << " from " << n << " photons");
    CHECK(std::fabs(channel(eb, k) - want) < 4.0 * want / std::sqrt(std::max(1.0, n)) + 0.02 * want);
  }
  // No volume photons in the surface map, none of the surface map in the
  // volume map: the volume map of the foggy slab stores inside the slab only.
  photon::TraceSettings vs = ts;
  vs.kind = MapKind::Volume;
  vs.maxBounces = 4;
  photon::TraceResult v = photon::tracePhotons(*foggy, vs, Progress{});
  REQUIRE(v.store.size() > 1000);
  for (size_t i = 0; i < v.store.size(); ++i) {
    float y = v.store.position(i).y;
    if (!(y > 0.499f && y < 1.501f)) FAIL("a volume photon outside the slab at y = " << y);
  }
}

TEST_CASE("media photons: the render builds a beam map for the volume kind, none without media") {
  auto d = pointInFog(Rgb(0.1f), Rgb(0.5f), Rgb(10.0f));
  auto s = Scene::build(d);
  RenderOptions opt;
  opt.method = RenderMethod::Time;
  opt.volumePhotons = 5000;
  PerMap<size_t> wanted = photonsWanted(opt);
  CHECK(wanted[MapKind::Volume] == 5000);
  PerMap<PhotonMapSettings> settings = photonMapSettingsFor(opt, wanted, 3, true, 0.0f);
  PhotonMaps maps = buildPhotonMaps(*s, settings, Progress{});
  const PhotonMap& vol = *maps[MapKind::Volume];
  REQUIRE(vol.size() >= 5000);
  CHECK(vol.beams.size() == vol.size());
  CHECK(vol.tree.size() == 0);
  CHECK(vol.bytesPerPhoton() <= 24.0);
  CHECK(vol.bytesPerPhoton() == doctest::Approx(vol.beams.bytesPerPhoton()));
  // No surface to store on: the surface maps are empty.
  CHECK(maps[MapKind::Global]->size() == 0);
  // A scene without media: no volume map even when asked for.
  auto plain = test::emptyScene(4, 4);
  plain.materials.push_back(test::diffuse(Rgb(0.5f)));
  plain.objects.push_back(test::quad({4, 4}, {0, 0, 0}, 0));
  plain.lights = d.lights;
  plain.lights[0].position = {0, 1, 0};
  plain.lights[0].medium = -1;
  auto sp = Scene::build(plain);
  REQUIRE(!sp->hasMedia());
  PhotonMaps none = buildPhotonMaps(*sp, settings, Progress{});
  CHECK(none[MapKind::Volume]->size() == 0);
  CHECK(none[MapKind::Volume]->warning.empty());
  // And by default (volumePhotons 0) the kind is not in use at all.
  RenderOptions plainOpt;
  CHECK(!mapKindInUse(plainOpt, MapKind::Volume));
  CHECK(mapKindInUse(plainOpt, MapKind::Global));
  CHECK(photonsWanted(plainOpt)[MapKind::Volume] == 0);
}

TEST_CASE("media photons: a scene without media reports no volume map, whatever --volume-photons says") {
  const std::string dir = test::makeTempDir();
  test::writeFile(dir + "/s.json", R"({"camera": {"position": [0, 1, 4], "target": [0, 0.5, 0], "resolution": [8, 6]},
    "materials": {"glass": {"type": "dielectric", "ior": 1.5}},
    "objects": [{"shape": {"type": "quad", "size": [4, 4]}}, {"shape": {"type": "sphere", "radius": 0.3},
                 "material": "glass", "transform": {"translate": [0, 0.6, 0]}}],
    "lights": [{"type": "point", "position": [0, 2, 0], "power": [50, 50, 50]}]})");
  for (const std::string extra : {"", " --volume-photons 5000"}) {
    test::CommandResult r = test::runTdpm("render '" + dir + "/s.json' -m time --photons 2000 --global-photons 1000 -q "
                                          "--stats -t 1 --spp 1 -o '" + dir + "/o.exr'" + extra);
    INFO(r.output);
    REQUIRE(r.exitCode == 0);
    CHECK(r.output.find("caustic photons:") != std::string::npos);
    CHECK(r.output.find("global photons:") != std::string::npos);
    CHECK(r.output.find("volume") == std::string::npos);
  }
}

TEST_CASE("media photons: progressive passes trace fresh volume photons with the pass's fixed beam kernel, kept in the state") {
  // The photon side of progressive media (the eye side and the renderer's
  // refusal are render/renderer.cpp's): pass 0's volume map is the pilot,
  // every pass's map a Fixed beam map; the pilot kernel and the paths per
  // pass go into the state and come back from its EXR attributes exactly.
  auto d = pointInFog(Rgb(0.1f), Rgb(0.5f), Rgb(10.0f));
  d.materials.push_back(test::diffuse(Rgb(0.5f)));
  d.objects.push_back(test::quad({6, 6}, {0, -1, 0}, 0));
  auto s = Scene::build(d);
  RenderOptions opt;
  opt.method = RenderMethod::Time;
  opt.progressive = true;
  opt.passes = 2;
  opt.spp = 1;
  opt.causticPhotons = 0;
  opt.globalPhotons = 2000;
  opt.volumePhotons = 3000;
  ProgressiveState state;
  RenderStats st;
  renderProgressive(*s, opt, state, Progress{}, st);
  REQUIRE(state.passesDone == 2);
  const ProgressiveMapPilot& v = state.pilot.maps[MapKind::Volume];
  CHECK(v.pathsPerPass > 0);
  CHECK(std::fmod(v.pathsPerPass, double(photon::kPathsPerBatch)) == 0.0);
  CHECK(v.radius > 0);
  CHECK(v.radius < 10.0);  // k-NN discs of 3000 photons in a fog of mean free path 1.7: about 2
  // Two passes of the same paths per pass: about twice the photons of one.
  CHECK(st.maps[MapKind::Volume].emitted == uint64_t(2 * v.pathsPerPass));
  CHECK(st.maps[MapKind::Volume].stored > 4000);
  REQUIRE(state.settings.count("volume_photons") == 1);
  image::ExrFile exr;
  exr.color = image::ImageRgb(s->camera.width(), s->camera.height(), Rgb(0.0f));
  addProgressiveState(state, exr);
  CHECK(exr.metadata.count("tdpm/progressive/scalar/kernel.volume.radius_1") == 1);
  std::optional<ProgressiveState> back = progressiveStateOf(exr, "p.exr");
  REQUIRE(back);
  CHECK(back->pilot == state.pilot);
  // A state without the volume map's setting carries none of its scalars.
  ProgressiveState plain = state;
  plain.settings.erase("volume_photons");
  image::ExrFile exr2;
  exr2.color = exr.color;
  addProgressiveState(plain, exr2);
  CHECK(exr2.metadata.count("tdpm/progressive/scalar/kernel.volume.radius_1") == 0);
  CHECK(exr2.metadata.count("tdpm/progressive/scalar/kernel.global.radius_1") == 1);
  std::optional<ProgressiveState> back2 = progressiveStateOf(exr2, "p.exr");
  REQUIRE(back2);
  CHECK(back2->pilot.maps[MapKind::Global] == state.pilot.maps[MapKind::Global]);
}
