// tests/test_sparse_estimate.cpp — the k-NN estimates where the search holds
// few photons (issue 24; docs/photon-map.md, "Few photons"): on synthetic
// photon sets of known density the mean of the standard, two-pass and 4D
// estimates is within 2% of the truth at every search size n from 2 to
// 10,000, and their 99.9th percentile is below a stated bound.
//
// Sets (plane z = 0, photons arriving from +z, total energy 1 J, shutter
// [0, 1]):
//   uniform   uniform over [0, 4]^2 and in time;
//   ramp      uniform in space, time density 0.5 + t (a gradient in time);
//   moving    a caustic line x ~ N(v t, 1), y uniform over [0, 4], moving
//             at v = 0.4 a shutter: queried on its flanks x = v t +- 1,
//             where the density is linear to third order in space and in
//             time, so that a symmetric kernel of any size has no
//             smoothing bias there and the tests see the small-count bias
//             alone.
// Truth: energy per area per time (time-dependent estimates) or its shutter
// average (the standard estimate).
//
// The 99.9th-percentile bound. With Poisson photons the standard estimate
// is rho (k-1) / G_k, G_k ~ Gamma(k) (the photon count of the disc the k-th
// closes, in units of its mean), and the 4D estimate likewise in its
// clipped ellipsoid; so the bound is the 99.9th percentile of
// (k-1) / G_k, computed here, times 1.15 (the sample quantile's error and
// the binomial, not Poisson, sets). The two-pass estimate is a product of
// that spatial factor (k_s - 1 inside the disc) and a time factor, the m-1
// kept photons over the window the m-th closes, (m-1) / (n' B_m),
// B_m ~ Beta(m, n' - m + 1) (m-th of n' uniform times); given n' the two are
// independent, so P(S T > s t) <= P(S > s) + P(T > t), and the bound is the
// product of their 99.95th percentiles (times 1.15). m >= 8
// (kMinTimePhotons) keeps the time factor's tail (P ~ x^-m) light.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/rng.h"
#include "estimate/estimators.h"
#include "photon/kdtree.h"
#include "photon/store.h"
#include "photon/temporal_select.h"
#include "render/renderer.h"
#include "scene/parse.h"
#include "scene_fixtures.h"

using namespace tdpm;
using namespace tdpm::estimate;

namespace {

enum class Set { Uniform, Ramp, Moving };
constexpr float kSide = 4.0f;   // the square / the line's length
constexpr float kSpeed = 0.4f;  // moving line, per shutter
constexpr size_t kPhotons = 400000;
// 4D: ellipsoid time extent d / 2, from 4 bins (n = 2: the photons lie on
// their bin centres in the 4D tree, and an ellipsoid thinner than a few
// bins sees that lattice) to 0.29 at n = 10,000 (inside [0, 1] for the
// queries at t in [0.3, 0.7], so the kernel stays symmetric).
constexpr float kKappa = 4.0f;

// phi(1) / 4: the moving line's density on its flanks (sigma 1, length 4).
const double kFlank = std::exp(-0.5) / std::sqrt(2.0 * kPi) / kSide;

struct SetMaps {
  photon::PhotonStore store{0.0f, 1.0f}, store4{0.0f, 1.0f};
  photon::KdTree tree, tree4;
};

void makeSet(SetMaps& m, Set set, uint64_t seed) {
  Rng rng(seed);
  m.store.reserve(kPhotons);
  const float q = 1.0f / float(kPhotons);
  for (size_t i = 0; i < kPhotons; ++i) {
    float t = rng.uniform(), x, y = kSide * rng.uniform();
    if (set == Set::Ramp) t = 0.5f * (-1.0f + std::sqrt(1.0f + 8.0f * t));  // density 0.5 + t
    if (set == Set::Moving) {
      float u1 = 1.0f - rng.uniform(), u2 = rng.uniform();
      x = kSpeed * t + std::sqrt(-2.0f * std::log(u1)) * std::cos(2.0f * kPi * u2);
    } else {
      x = kSide * rng.uniform();
    }
    m.store.add({x, y, 0.0f}, Rgb(q), {0, 0, 1}, t);
  }
  m.store4 = m.store;
  m.tree = photon::KdTree::build(m.store, {});
  photon::KdBuildOptions o4;
  o4.spaceTime = true;
  o4.kappa = kKappa;
  m.tree4 = photon::KdTree::build(m.store4, o4);
}

struct Q {
  float x, y, t;
  double truth;
};

// Query points well inside the set (the largest kernel, n = 10,000, has a
// radius of about 0.36 in space and 0.2 in 4D time).
std::vector<Q> queries(Set set, Method method, int count, uint64_t seed, bool centreTime) {
  Rng rng(seed);
  std::vector<Q> qs(static_cast<size_t>(count));
  for (Q& q : qs) {
    q.t = centreTime ? 0.5f : 0.3f + 0.4f * rng.uniform();
    q.y = 1.0f + 2.0f * rng.uniform();
    if (set == Set::Moving) {
      q.x = kSpeed * q.t + (rng.uniform() < 0.5f ? -1.0f : 1.0f);
      q.truth = kFlank;
    } else {
      q.x = 1.0f + 2.0f * rng.uniform();
      double pt = set == Set::Ramp ? 0.5 + double(q.t) : 1.0;
      q.truth = (method == Method::Standard ? 1.0 : pt) / double(kSide * kSide);
    }
  }
  return qs;
}

// ---- the bounds ----
// P(Gamma(k) < x) for integer k (Poisson tail), in log space for large k.
double gammaCdf(int k, double x) {
  double s = 0.0, lx = std::log(x);
  for (int i = 0; i < k; ++i) s += std::exp(double(i) * lx - x - std::lgamma(double(i) + 1.0));
  return 1.0 - std::min(s, 1.0);
}
// P(Beta(m, n - m + 1) < x) = P(Binomial(n, x) >= m).
double betaCdf(int m, int n, double x) {
  double s = 0.0;
  for (int i = m; i <= n; ++i)
    s += std::exp(std::lgamma(n + 1.0) - std::lgamma(i + 1.0) - std::lgamma(n - i + 1.0) + i * std::log(x) +
                  (n - i) * std::log1p(-x));
  return std::min(s, 1.0);
}
template <class Cdf>
double lowerQuantile(Cdf cdf, double p, double lo, double hi) {
  for (int it = 0; it < 100; ++it) {
    double mid = 0.5 * (lo + hi);
    (cdf(mid) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}
// Upper (1 - p) quantile of (k-1) / G_k.
double spatialTail(int k, double p) {
  return (k - 1) / lowerQuantile([k](double x) { return gammaCdf(k, x); }, p, 0.0, 2.0 * k + 50.0);
}
// Upper (1 - p) quantile of (m-1) / (n B_m).
double timeTail(int m, int n, double p) {
  return (m - 1) / (n * lowerQuantile([m, n](double x) { return betaCdf(m, n, x); }, p, 1e-12, 1.0 - 1e-12));
}
double boundFor(Method method, int n, float fraction) {
  if (n < 2) return 0.0;
  if (method != Method::TimeTwoPass) return 1.15 * spatialTail(n, 1e-3);
  int inside = n - 1;
  int m = std::max(photon::keptCount(fraction, inside), kMinTimePhotons);
  double t = m >= inside ? 1.0 : timeTail(m, inside, 5e-4);
  return 1.15 * spatialTail(n, 5e-4) * t;
}

struct Result {
  double mean, p999;
  int count;
};

Result run(const SetMaps& m, Method method, int n, const std::vector<Q>& qs, float maxDt = 1e30f) {
  Options o;
  o.method = method;
  o.k = n;
  o.ks = n;
  o.fraction = 0.5f;
  o.maxTimeDistance = maxDt;
  Gatherer g(method == Method::SpaceTime4D ? m.tree4 : m.tree, o);
  const ConstantBrdf one{Rgb(1.0f)};
  std::vector<double> r;
  r.reserve(qs.size());
  double sum = 0.0;
  for (const Q& q : qs) {
    double v = g.radiance({q.x, q.y, 0.0f}, {0, 0, 1}, {0, 0, 1}, q.t, one).r / q.truth;
    sum += v;
    r.push_back(v);
  }
  size_t at = std::min(r.size() - 1, size_t(0.999 * double(r.size())));
  std::nth_element(r.begin(), r.begin() + long(at), r.end());
  return {sum / double(r.size()), r[at], int(r.size())};
}

const int kSizes[] = {2, 3, 4, 5, 6, 8, 9, 10, 12, 16, 17, 24, 32, 64, 128, 512, 2000, 10000};

// Queries per size: enough for the mean's error (the estimate's relative
// spread is ~1/sqrt(n-1), infinite variance at n = 2) to be well below 2%.
// Above ~500 the map's own fluctuation over the query region (~0.3%)
// dominates, so 1,000 queries do.
int queryCount(int n) { return std::clamp(600000 / n, 1000, 150000); }

// The sets, built once for every test case that reads them.
const SetMaps& setMaps(Set set) {
  static SetMaps maps[3];
  static bool built[3] = {false, false, false};
  int si = int(set);
  if (!built[si]) {
    makeSet(maps[si], set, 100 + uint64_t(si));
    built[si] = true;
  }
  return maps[si];
}

void checkSet(Set set, Method method, uint64_t seed, bool centreTime) {
  const int si = int(set);
  const SetMaps& map = setMaps(set);
  for (int n : kSizes) {
    CAPTURE(n);
    std::vector<Q> qs = queries(set, method, queryCount(n), seed + uint64_t(n), centreTime);
    Result res = run(map, method, n, qs);
    double bound = boundFor(method, n, 0.5f);
    MESSAGE("set " << si << " method " << int(method) << " n " << n << ": mean " << res.mean << " p99.9 "
                   << res.p999 << " (bound " << bound << ", " << res.count << " queries)");
    CHECK(std::fabs(res.mean - 1.0) < 0.02);
    CHECK(res.p999 < bound);
  }
}

}  // namespace

TEST_CASE("sparse estimates: the standard estimate's mean is the density at every n, tail bounded") {
  checkSet(Set::Uniform, Method::Standard, 1, false);
  checkSet(Set::Ramp, Method::Standard, 2, false);
}

TEST_CASE("sparse estimates: two-pass, uniform and a gradient in time") {
  checkSet(Set::Uniform, Method::TimeTwoPass, 3, false);
  // A gradient: right where the window is symmetric about the query. At
  // mid-shutter that is every n; below kMinTimePhotons kept the window is
  // the shutter, whose mean is the density at its middle only.
  checkSet(Set::Ramp, Method::TimeTwoPass, 4, true);
}

TEST_CASE("sparse estimates: two-pass, a moving caustic line") {
  checkSet(Set::Moving, Method::TimeTwoPass, 5, false);
}

TEST_CASE("sparse estimates: 4D, uniform") { checkSet(Set::Uniform, Method::SpaceTime4D, 6, false); }

TEST_CASE("sparse estimates: 4D, a gradient in time") { checkSet(Set::Ramp, Method::SpaceTime4D, 7, false); }

TEST_CASE("sparse estimates: 4D, a moving caustic line") { checkSet(Set::Moving, Method::SpaceTime4D, 8, false); }

TEST_CASE("sparse estimates: a maximum time distance gives a known window (count over it)") {
  const SetMaps& m = setMaps(Set::Uniform);
  for (int n : {2, 9, 16, 64, 512}) {
    CAPTURE(n);
    std::vector<Q> qs = queries(Set::Uniform, Method::TimeTwoPass, queryCount(n), 40 + uint64_t(n), false);
    Result res = run(m, Method::TimeTwoPass, n, qs, 0.05f);
    MESSAGE("max dt 0.05, n " << n << ": mean " << res.mean);
    CHECK(std::fabs(res.mean - 1.0) < 0.02);
  }
}

namespace {
// scenes/cube-caustic.json at 32x24, 4 spp, 20,000 caustic and 500 global
// photons (the final gather reads a sparse global map); image mean.
double cubeMean(bool fourD, int k, uint64_t seed, RenderStats* stats = nullptr, float maxRadius = 0.0f) {
  scene::SceneDescription d = scene::loadScene(std::string(TDPM_SOURCE_DIR) + "/scenes/cube-caustic.json");
  d.camera.width = 32;
  d.camera.height = 24;
  auto scene = Scene::build(d);
  RenderOptions o;
  o.method = RenderMethod::Time;
  o.spaceTime4D = fourD;
  o.spp = 4;
  o.seed = seed;
  o.causticPhotons = 20000;
  o.globalPhotons = 500;
  o.estimate.k = k;
  o.estimate.ks = k;
  if (maxRadius > 0.0f) {
    o.estimate.maxRadius = maxRadius;
    o.maxDtFraction = 2.0f;  // and no time bound: every search keeps its f k_s
  }
  RenderStats st;
  Film f = render(*scene, o, Progress{}, st);
  if (stats) *stats = st;
  double sum = 0.0;
  for (const Rgb& c : f.color) sum += c.average();
  return sum / double(f.color.size());
}
}  // namespace

// Issue 24: the 4D estimate clipped its ellipsoid to the time range of the
// photons it found; on a sparse map that range is far shorter than the
// ellipsoid and the image mean was 2.3-2.9x the two-pass one and the path
// tracer's (32x24, 16 spp, 4 seeds; now 0.96-1.01x a 2048-spp path-traced
// reference, two-pass 0.97-1.02x). The two estimates read the same photons
// (same seed), so their ratio is far less noisy than either against a
// reference: measured 0.978-0.989 after the fix.
TEST_CASE("sparse estimates: cube-caustic with 500 global photons, 4D agrees with two-pass at any k") {
  for (uint64_t seed : {1, 2}) {
    CAPTURE(seed);
    double two = cubeMean(false, 100, seed);
    for (int k : {20, 100, 400}) {
      CAPTURE(k);
      double four = cubeMean(true, k, seed);
      MESSAGE("seed " << seed << " k " << k << ": 4D " << four << " two-pass (k_s 100) " << two);
      CHECK(four / two > 0.95);
      CHECK(four / two < 1.05);
    }
  }
}

// --stats: estimates per map and those from fewer than kFewPhotons photons.
// With 500 global photons and the default maximum radius (2% of the scene's
// diagonal) nearly every global estimate reads a handful (measured 1118 of
// 1122); with an unbounded radius and time distance every search finds its
// k = 100 and keeps 50.
TEST_CASE("sparse estimates: --stats counts the estimates from few photons, per map") {
  RenderStats st;
  cubeMean(false, 100, 1, &st);
  CHECK(st.maps[MapKind::Caustic].estimates + st.maps[MapKind::Global].estimates == st.standardEstimates + st.timeEstimates);
  CHECK(st.maps[MapKind::Global].estimates > 0);
  CHECK(st.maps[MapKind::Global].fewEstimates > st.maps[MapKind::Global].estimates / 2);
  CHECK(st.maps[MapKind::Caustic].fewEstimates <= st.maps[MapKind::Caustic].estimates);
  cubeMean(false, 100, 1, &st, 1e6f);
  CHECK(st.maps[MapKind::Global].estimates > 0);
  CHECK(st.maps[MapKind::Global].fewEstimates == 0);
  CHECK(st.maps[MapKind::Caustic].fewEstimates == 0);
}

namespace {
// scenes/static-room.json with tall_block moving from x-0.4 to x+0.4 over
// the shutter, the global map seen directly (--global-direct --gather 0
// --photons 0), 80x60, 8 spp: image mean.
double movingRoomMean(RenderMethod method, size_t globalPhotons) {
  scene::SceneDescription d = scene::loadScene(std::string(TDPM_SOURCE_DIR) + "/scenes/static-room.json");
  for (scene::ObjectDesc& o : d.objects)
    if (o.name == "tall_block") o.motion = test::translation({-0.4f, 0, 0}, {0.4f, 0, 0});
  d.camera.width = 80;
  d.camera.height = 60;
  auto scene = Scene::build(d);
  RenderOptions o;
  o.method = method;
  o.spp = 8;
  o.seed = 2;
  o.causticPhotons = 0;
  o.globalPhotons = globalPhotons;
  o.gatherRays = 0;
  o.visualizeGlobal = true;
  RenderStats st;
  Film f = render(*scene, o, Progress{}, st);
  double sum = 0.0;
  for (const Rgb& c : f.color) sum += c.average();
  return sum / double(f.color.size());
}
}  // namespace

// Issue 24's own scene: time over standard was 1.343 at 2,000 global
// photons and 1.060 at 100,000 (a bias that grew as photons got sparse);
// now 1.046 and 1.055. The ~5% left at every count is on the moving block,
// where the standard estimate is the wrong one (it reads the block's
// photons of the whole shutter; against a path-traced reference the full
// render's block is 1.004 with time, 0.966 with standard: docs/photon-map.md).
// So the test asserts what the fix is about: the ratio no longer depends on
// the photon count.
TEST_CASE("sparse estimates: the moving static-room's global map, time over standard does not grow as photons get few") {
  double sparse = movingRoomMean(RenderMethod::Time, 2000) / movingRoomMean(RenderMethod::Standard, 2000);
  double dense = movingRoomMean(RenderMethod::Time, 100000) / movingRoomMean(RenderMethod::Standard, 100000);
  MESSAGE("time / standard: 2,000 global photons " << sparse << ", 100,000 " << dense);
  CHECK(std::fabs(sparse - dense) < 0.03);
  CHECK(sparse < 1.08);
}
