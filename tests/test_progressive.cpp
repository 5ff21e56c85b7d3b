// tests/test_progressive.cpp — the progressive pass loop (render/progressive.h)
// against analytic answers and an independent reference: on the moving
// plane (analytic) the error of `time --progressive` falls at the slope its
// alpha predicts, time and accumulation converge to the same value while
// standard does not; a point-light caustic on a moving floor converges to
// the mean of frozen-time static renders; resuming a state gives the very
// image of one longer run; any thread count gives the same image.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "photon/tracer.h"
#include "render/progressive.h"
#include "render/renderer.h"
#include "moving_plane.h"
#include "progressive_checks.h"
#include "scene_fixtures.h"

using namespace tdpm;

namespace {


// The moving plane of tests/test_photon_render.cpp: a diffuse plane moving
// along its normal from y = 0 to y = -1 over the shutter, a point light at
// (0, 2, 0), the camera above looking down.
scene::SceneDescription movingPlane(int res) { return test::movingPlaneScene(res); }

// Exact pixel mean: radiance rho/pi I cos / d^2 of the plane point each
// sub-pixel ray meets at each time, averaged over a fine grid of both.
double analyticPixel(const Camera& cam, int x, int y) { return test::movingPlanePixel(cam, Shutter{0, 1}, x, y); }

// The global map seen directly (no final gather, no direct light): the
// estimate alone, as in test_photon_render.cpp.
RenderOptions planeOptions(const std::string& method, uint64_t seed) {
  RenderOptions o;
  o.method = *parseRenderMethod(method);
  o.progressive = true;
  o.spp = 2;
  o.seed = seed;
  o.causticPhotons = 0;
  o.globalPhotons = 4000;
  o.visualizeGlobal = true;
  o.estimate.k = 50;
  o.estimate.ks = 50;
  o.estimate.maxRadius = 1.0f;
  return o;
}

// Relative MSE of a film against per-pixel references, and the mean ratio.
struct Error {
  double relMse = 0, ratio = 0;
};
Error errorOf(const Film& f, const std::vector<double>& ref) {
  Error e;
  double got = 0, want = 0;
  for (size_t i = 0; i < ref.size(); ++i) {
    double d = (double(f.color[i].r) - ref[i]) / ref[i];
    e.relMse += d * d;
    got += f.color[i].r;
    want += ref[i];
  }
  e.relMse /= double(ref.size());
  e.ratio = got / want;
  return e;
}

std::vector<double> planeReference(const Scene& s) {
  std::vector<double> ref;
  for (int y = 0; y < s.camera.height(); ++y)
    for (int x = 0; x < s.camera.width(); ++x) ref.push_back(analyticPixel(s.camera, x, y));
  return ref;
}

// Runs passes up to each count in `checkpoints` on one state (the loop
// continues it), returning the film's error at each.
std::vector<Error> convergence(const Scene& s, RenderOptions o, const std::vector<double>& ref,
                               const std::vector<int>& checkpoints) {
  ProgressiveState state;
  std::vector<Error> out;
  for (int n : checkpoints) {
    o.passes = n;
    RenderStats st;
    Film f = renderProgressive(s, o, state, Progress{}, st);
    out.push_back(errorOf(f, ref));
  }
  return out;
}


}  // namespace

TEST_CASE("progressive: kernel schedule shrinks the volume by (i + alpha)/(i + 1) per pass") {
  // V_j / V_1 = prod_{m=1}^{j-1} (m + a)/(m + 1) ~ Gamma(2) j^(a-1) / Gamma(1 + a).
  CHECK(kernelScale(0, 0.5, 3) == 1.0);
  CHECK(std::pow(kernelScale(1, 0.5, 3), 3) == doctest::Approx(1.5 / 2.0));
  CHECK(std::pow(kernelScale(2, 0.5, 2), 2) == doctest::Approx(1.5 / 2.0 * 2.5 / 3.0));
  double v = std::pow(kernelScale(9999, 4.0 / 7.0, 3), 3);
  CHECK(v == doctest::Approx(std::pow(10000.0, 4.0 / 7.0 - 1.0) / std::tgamma(1.0 + 4.0 / 7.0)).epsilon(0.01));
  // Accumulation's pass times: a rotated radical inverse, stratified: any 2^m
  // consecutive passes from 0 fill the 2^m strata once each.
  std::vector<int> strata(16, 0);
  for (int p = 0; p < 16; ++p) strata[size_t(accumulationPassTime(p, 7) * 16)]++;
  for (int c : strata) CHECK(c == 1);
}

TEST_CASE("progressive: N passes continued for N more equal 2N passes in one run, for any thread count") {
  auto d = movingPlane(8);
  d.materials.push_back(scene::MaterialDesc{});
  d.materials.back().type = scene::MaterialDesc::Type::Mirror;
  auto s = Scene::build(d);
  for (const char* method : {"time", "accumulation", "standard"}) {
    CAPTURE(method);
    RenderOptions o = planeOptions(method, 3);
    o.visualizeGlobal = false;  // direct light, final gather and both maps
    o.causticPhotons = 1000;
    RenderStats st;
    ProgressiveState whole = test::checkResumeAndThreads(*s, o, st);
    CHECK(whole.passesDone == 4);
  }
}

namespace {
struct Curve {
  std::vector<double> mse, ratio;
};
Curve meanCurve(const Scene& s, const std::string& method, const std::vector<double>& ref, const std::vector<int>& cps,
                int seeds, int firstSeed) {
  Curve c{std::vector<double>(cps.size(), 0.0), std::vector<double>(cps.size(), 0.0)};
  for (int seed = firstSeed; seed < firstSeed + seeds; ++seed) {
    std::vector<Error> e = convergence(s, planeOptions(method, uint64_t(seed)), ref, cps);
    for (size_t i = 0; i < cps.size(); ++i) {
      c.mse[i] += e[i].relMse / seeds;
      c.ratio[i] += e[i].ratio / seeds;
    }
  }
  for (size_t i = 0; i < cps.size(); ++i) MESSAGE(method << " N=" << cps[i] << " relMSE=" << c.mse[i] << " ratio=" << c.ratio[i]);
  return c;
}
// Least-squares slope of log y against log x.
double logLogSlope(const std::vector<int>& xs, const std::vector<double>& ys) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0, n = double(xs.size());
  for (size_t i = 0; i < xs.size(); ++i) {
    double x = std::log(double(xs[i])), y = std::log(ys[i]);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}
}  // namespace

TEST_CASE("progressive: on the moving plane the error of time falls at the slope alpha predicts") {
  // docs/photon-map.md: with the space-time kernel (d = 3) and alpha = 4/7
  // the relative MSE falls as N^(-4/7) once bias and variance are balanced.
  auto s = Scene::build(movingPlane(8));
  std::vector<double> ref = planeReference(*s);
  const std::vector<int> cps = {4, 8, 16, 32};
  Curve c = meanCurve(*s, "time", ref, cps, 4, 1);
  double slope = logLogSlope(cps, c.mse);
  MESSAGE("time: log-log slope of relMSE " << slope << " (predicted " << -4.0 / 7.0 << ")");
  CHECK(slope == doctest::Approx(-4.0 / 7.0).epsilon(0.35));
  CHECK(c.ratio.back() == doctest::Approx(1.0).epsilon(0.03));
}

TEST_CASE("progressive: time and accumulation converge to the analytic value, standard does not") {
  auto s = Scene::build(movingPlane(8));
  std::vector<double> ref = planeReference(*s);
  const std::vector<int> cps = {4, 16};
  Curve t = meanCurve(*s, "time", ref, cps, 2, 11);
  Curve a = meanCurve(*s, "accumulation", ref, cps, 2, 11);
  Curve st = meanCurve(*s, "standard", ref, cps, 1, 11);
  CHECK(t.mse[1] < t.mse[0] * 0.5);
  CHECK(a.mse[1] < a.mse[0] * 0.5);
  CHECK(t.ratio[1] == doctest::Approx(1.0).epsilon(0.03));
  CHECK(a.ratio[1] == doctest::Approx(1.0).epsilon(0.02));
  CHECK(std::fabs(t.ratio[1] - a.ratio[1]) < 0.03);
  // standard averages photons of the times the plane was within r of the
  // gather point: a fraction ~ 2r / (v ts) of the shutter that shrinks with
  // r, so its estimate falls towards 0 as the passes go on.
  CHECK(st.ratio[0] < 0.7);
  CHECK(st.ratio[1] < st.ratio[0] - 0.03);
  CHECK(st.mse[1] > st.mse[0]);
}

namespace {
// A point light above a glass ball focusing onto a diffuse floor that moves
// down through the focus over the shutter; the camera looks at the caustic
// from the side. floorDrop < 0: the floor moves; >= 0: frozen at that drop.
scene::SceneDescription causticScene(float frozenDrop) {
  auto d = test::emptyScene(20, 20);
  d.camera.position = {0, 1.2f, 2.2f};
  d.camera.target = {0, -0.4f, 0};
  d.camera.fovDegrees = 16;
  d.materials.push_back(test::diffuse(Rgb(0.8f)));
  scene::MaterialDesc glass;
  glass.type = scene::MaterialDesc::Type::Dielectric;
  glass.ior = 1.5f;
  d.materials.push_back(glass);
  auto floor = test::quad({4, 4}, {0, -0.2f - std::max(0.0f, frozenDrop), 0}, 0);
  if (frozenDrop < 0) floor.motion = test::translation({0, 0, 0}, {0, -0.6f, 0});
  d.objects.push_back(floor);
  d.objects.push_back(test::sphere(0.3f, {0, 0.5f, 0}, 1));
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Point;
  l.position = {0, 2.0f, 0};
  l.power = Rgb(4 * kPi * 2.0f);
  d.lights.push_back(l);
  return d;
}

RenderOptions causticOptions() {
  RenderOptions o;
  o.spp = 4;
  o.seed = 5;
  o.globalPhotons = 0;
  o.gatherRays = 0;  // direct light + the caustic map
  return o;
}
}  // namespace

TEST_CASE("progressive: a point-light caustic on a moving floor converges to the mean of frozen-time renders") {
  // Reference (a different method): the floor frozen at 16 stratified drops,
  // each rendered static with 50k caustic photons and the k-NN estimate;
  // the time average of a pixel is the mean of the 16 (each frozen image
  // uses the same shutter length, so photon energies agree).
  const int frames = 16;
  std::vector<double> ref;
  for (int f = 0; f < frames; ++f) {
    float t = (f + 0.5f) / frames;
    auto s = Scene::build(causticScene(0.6f * t));
    RenderOptions o = causticOptions();
    o.method = RenderMethod::Static;
    o.causticPhotons = 50000;
    o.estimate.k = 50;
    RenderStats st;
    Film film = render(*s, o, Progress{}, st);
    if (ref.empty()) ref.assign(film.color.size(), 0.0);
    for (size_t i = 0; i < ref.size(); ++i) ref[i] += double(film.color[i].luminance()) / frames;
  }
  auto s = Scene::build(causticScene(-1.0f));
  RenderOptions o = causticOptions();
  o.method = RenderMethod::Time;
  o.progressive = true;
  o.causticPhotons = 10000;
  o.estimate.k = 50;
  o.estimate.ks = 50;
  ProgressiveState state;
  std::vector<double> err;
  double refSum = 0;
  for (double v : ref) refSum += v * v;
  for (int n : {2, 8, 32}) {
    o.passes = n;
    RenderStats st;
    Film f = renderProgressive(*s, o, state, Progress{}, st);
    double e = 0;
    for (size_t i = 0; i < ref.size(); ++i) {
      double d = double(f.color[i].luminance()) - ref[i];
      e += d * d;
    }
    err.push_back(std::sqrt(e / refSum));
    MESSAGE("caustic: " << n << " passes, relative L2 error " << err.back());
  }
  // The reference has its own error (k-NN bias, 16 instants): the fall
  // flattens towards it.
  CHECK(err[1] < 0.85 * err[0]);
  CHECK(err[2] < 0.6 * err[0]);
}

TEST_CASE("progressive: a pass's photon paths continue the path indices of the passes before it") {
  auto s = Scene::build(movingPlane(8));
  photon::TraceSettings t;
  t.kind = photon::MapKind::Global;
  t.storedWanted = 1;
  t.sampler = SamplerKind::Sobol;
  t.seed = 4;
  const uint64_t P = 4 * photon::kPathsPerBatch;
  auto trace = [&](uint64_t first, uint64_t paths) {
    photon::PathRange range;
    range.firstPath = first;
    range.paths = paths;
    return photon::tracePassPhotons(*s, t, range, Progress{});
  };
  photon::TraceResult whole = trace(0, 2 * P), a = trace(0, P), b = trace(P, P);
  CHECK(whole.emitted == 2 * P);
  CHECK(a.emitted == P);
  REQUIRE(a.store.size() + b.store.size() == whole.store.size());
  for (size_t i = 0; i < whole.store.size(); ++i) {
    const photon::PhotonStore& part = i < a.store.size() ? a.store : b.store;
    size_t j = i < a.store.size() ? i : i - a.store.size();
    CHECK(lengthSquared(part.position(j) - whole.store.position(i)) == 0.0f);
    CHECK(part.timeBin(j) == whole.store.timeBin(i));
  }
  // Past 2^32 paths the sequences take new scrambles: not the first paths again.
  photon::TraceResult far = trace(uint64_t(1) << 32, P);
  int same = 0;
  for (size_t i = 0; i < std::min(far.store.size(), a.store.size()); ++i) same += lengthSquared(far.store.position(i) - a.store.position(i)) == 0.0f;
  CHECK(same == 0);
}

TEST_CASE("progressive: pass kernels follow alpha, and the half window stops at one time bin keeping the volume") {
  auto s = Scene::build(movingPlane(8));  // shutter [0, 1]: one bin is 1/256 s
  ProgressiveState st;
  st.pilot.done = true;
  st.pilot.maps[MapKind::Caustic].radius = 0.1;
  st.pilot.maps[MapKind::Caustic].halfWindow = 0.05;
  st.pilot.maps[MapKind::Caustic].spatialRadius = 0.2;
  st.pilot.maps[MapKind::Global].radius = 0.1;
  st.pilot.maps[MapKind::Global].halfWindow = 1.1 / 256.0;  // 1.1 bins
  st.pilot.maps[MapKind::Global].spatialRadius = 0.2;
  RenderOptions o;
  o.method = RenderMethod::Time;
  for (float alpha : {0.0f, 0.5f}) {
    o.alpha = alpha;
    double a3 = alpha > 0 ? alpha : 4.0 / 7.0;
    PassKernels k = kernelsForPass(st, o, *s, 9);
    CHECK(k[MapKind::Caustic].radius == doctest::Approx(0.1 * kernelScale(9, a3, 3)));
    CHECK(k[MapKind::Caustic].halfWindow == doctest::Approx(0.05 * kernelScale(9, a3, 3)));
    CHECK(k[MapKind::Caustic].spatialRadius == doctest::Approx(0.2 * kernelScale(9, 2.0 / 3.0, 2)));  // time's fallback: 2/3
    // The global window would fall below a bin: floored there, r^2 h keeps the schedule.
    double s3 = kernelScale(9, a3, 3);
    CHECK(1.1 * s3 < 1.0);
    CHECK(k[MapKind::Global].halfWindow == doctest::Approx(1.0 / 256.0));
    CHECK(double(k[MapKind::Global].radius) * k[MapKind::Global].radius * k[MapKind::Global].halfWindow ==
          doctest::Approx(0.01 * s3 * s3 * (1.1 / 256.0) * s3).epsilon(1e-4));
  }
  o.method = RenderMethod::Standard;
  o.alpha = 0.5f;
  CHECK(kernelsForPass(st, o, *s, 9)[MapKind::Caustic].spatialRadius == doctest::Approx(0.2 * kernelScale(9, 0.5, 2)));
}
