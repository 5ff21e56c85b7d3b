// bench/bench_photon.cpp — the photon map core, one thread unless stated:
// k-NN of our left-balanced tree against stock nanoflann on the same 1M
// surface-like photons (floor, wall, concentrated caustic), queries in random
// and in Morton (spatially coherent) order; SIMD temporal selection against
// std::nth_element and the quickselect reference at k_s = 200; a whole
// time-dependent query against a standard one; tree build on 1 and 2
// threads; bytes per photon. Compare ratios within one run (bench/README.md).
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "core/rng.h"
#include "estimate/estimators.h"
#include "estimate/fixed_kernel.h"
#include "photon/kdtree.h"
#include "photon/store.h"
#include "photon/temporal_select.h"

#if __has_include(<nanoflann.hpp>)
#include <nanoflann.hpp>
#define TDPM_HAVE_NANOFLANN 1
#endif

using namespace tdpm;

namespace {

constexpr size_t kPhotons = 1000000;
constexpr int kQueries = 1 << 16;

// Floor 50%, wall 30%, caustic (tight Gaussian on the floor) 20%; a time
// uniform in the shutter, except the caustic, whose time follows x (a moving
// caustic, as in the method's canonical case).
photon::PhotonStore makeSurfacePhotons(size_t n, uint64_t seed) {
  photon::PhotonStore s(0.0f, 1.0f);
  s.reserve(n);
  Rng rng(seed);
  for (size_t i = 0; i < n; ++i) {
    float c = rng.uniform(), t = rng.uniform();
    Vec3f p, wi;
    if (c < 0.5f) {
      p = {rng.uniform() * 10.0f - 5.0f, 0.0f, rng.uniform() * 10.0f - 5.0f};
      wi = {0.0f, 1.0f, 0.0f};
    } else if (c < 0.8f) {
      p = {rng.uniform() * 10.0f - 5.0f, rng.uniform() * 6.0f, -5.0f};
      wi = {0.0f, 0.0f, 1.0f};
    } else {
      float u1 = 1.0f - rng.uniform(), u2 = rng.uniform();
      float r = 0.15f * std::sqrt(-2.0f * std::log(u1));
      p = {1.0f + r * std::cos(6.2831853f * u2) + 0.5f * t, 0.0f, 0.5f + r * std::sin(6.2831853f * u2)};
      wi = normalize(Vec3f(0.2f, 1.0f, 0.1f));
    }
    s.add(p, Rgb(1e-6f), wi, t);
  }
  return s;
}

uint32_t spread10(uint32_t v) {  // 10 bits -> every third bit
  v &= 0x3FF;
  v = (v | (v << 16)) & 0x030000FF;
  v = (v | (v << 8)) & 0x0300F00F;
  v = (v | (v << 4)) & 0x030C30C3;
  v = (v | (v << 2)) & 0x09249249;
  return v;
}

struct Fixture {
  photon::PhotonStore store;
  photon::KdTree tree;
  photon::PhotonStore store4;
  photon::KdTree tree4;
  std::vector<Vec3f> randomQueries, mortonQueries;
  std::vector<float> queryTimes;
#ifdef TDPM_HAVE_NANOFLANN
  struct Cloud {
    std::vector<std::array<float, 3>> pts;
    size_t kdtree_get_point_count() const { return pts.size(); }
    float kdtree_get_pt(size_t i, size_t d) const { return pts[i][d]; }
    template <class B>
    bool kdtree_get_bbox(B&) const { return false; }
  } cloud;
  using Nano = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Cloud>, Cloud, 3>;
  std::unique_ptr<Nano> nano;
#endif

  Fixture() {
    store = makeSurfacePhotons(kPhotons, 1);
    store4 = makeSurfacePhotons(kPhotons, 1);
    tree = photon::KdTree::build(store);
    photon::KdBuildOptions o4;
    o4.spaceTime = true;
    o4.kappa = 1.0f;
    tree4 = photon::KdTree::build(store4, o4);
    // Gather points where the eye would find them: on the same surfaces.
    photon::PhotonStore q = makeSurfacePhotons(kQueries, 2);
    Rng rng(3);
    for (int i = 0; i < kQueries; ++i) {
      randomQueries.push_back(q.position(size_t(i)));
      queryTimes.push_back(rng.uniform());
    }
    mortonQueries = randomQueries;
    auto code = [](Vec3f p) {
      auto c = [](float v) { return uint32_t(std::clamp((v + 5.0f) / 10.0f * 1023.0f, 0.0f, 1023.0f)); };
      return spread10(c(p.x)) | (spread10(c(p.y)) << 1) | (spread10(c(p.z)) << 2);
    };
    std::sort(mortonQueries.begin(), mortonQueries.end(), [&](Vec3f a, Vec3f b) { return code(a) < code(b); });
#ifdef TDPM_HAVE_NANOFLANN
    cloud.pts.resize(store.size());
    for (size_t i = 0; i < store.size(); ++i) cloud.pts[i] = {store.xs()[i], store.ys()[i], store.zs()[i]};
    nano = std::make_unique<Nano>(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
    nano->buildIndex();
#endif
  }
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

const std::vector<Vec3f>& queriesFor(const benchmark::State& state) {
  return state.range(1) ? fixture().mortonQueries : fixture().randomQueries;
}

// ---- k-NN ----

void BM_KnnOurs(benchmark::State& state) {
  Fixture& f = fixture();
  const auto& qs = queriesFor(state);
  int k = int(state.range(0));
  photon::KnnQuery q(k);
  size_t i = 0;
  for (auto _ : state) {
    int n = f.tree.knn(qs[i++ & (kQueries - 1)], k, std::numeric_limits<float>::infinity(), q);
    benchmark::DoNotOptimize(n);
    benchmark::DoNotOptimize(q.radius2);
  }
  state.SetItemsProcessed(int64_t(state.iterations()));
  state.counters["bytes_per_photon"] = f.tree.bytesPerPhoton();
}
BENCHMARK(BM_KnnOurs)->ArgsProduct({{100, 200}, {0, 1}})->ArgNames({"k", "morton"});

#ifdef TDPM_HAVE_NANOFLANN
void BM_KnnNanoflann(benchmark::State& state) {
  Fixture& f = fixture();
  const auto& qs = queriesFor(state);
  size_t k = size_t(state.range(0));
  std::vector<uint32_t> idx(k);
  std::vector<float> d2(k);
  size_t i = 0;
  for (auto _ : state) {
    Vec3f p = qs[i++ & (kQueries - 1)];
    float qp[3] = {p.x, p.y, p.z};
    size_t n = f.nano->knnSearch(qp, k, idx.data(), d2.data());
    benchmark::DoNotOptimize(n);
    benchmark::DoNotOptimize(d2.data());
  }
  state.SetItemsProcessed(int64_t(state.iterations()));
}
BENCHMARK(BM_KnnNanoflann)->ArgsProduct({{100, 200}, {0, 1}})->ArgNames({"k", "morton"});
#endif

// 4D k-NN, for reference (no baseline).
void BM_Knn4D(benchmark::State& state) {
  Fixture& f = fixture();
  const auto& qs = queriesFor(state);
  int k = int(state.range(0));
  photon::KnnQuery q(k);
  size_t i = 0;
  for (auto _ : state) {
    size_t j = i++ & (kQueries - 1);
    int n = f.tree4.knn4(qs[j], f.queryTimes[j], k, std::numeric_limits<float>::infinity(), q);
    benchmark::DoNotOptimize(n);
  }
  state.SetItemsProcessed(int64_t(state.iterations()));
}
BENCHMARK(BM_Knn4D)->ArgsProduct({{100}, {0, 1}})->ArgNames({"k", "morton"});

// ---- temporal selection at k_s = 200 ----

struct SelectData {
  static constexpr int kSets = 1024, kS = 200;
  std::vector<uint8_t> bins;  // kSets x (kS + padding)
  std::vector<float> u;
  SelectData() {
    Fixture& f = fixture();
    photon::KnnQuery q(kS);
    int stride = kS + photon::kSelectPadding;
    bins.resize(size_t(kSets) * size_t(stride));
    for (int s = 0; s < kSets; ++s) {
      f.tree.knn(f.randomQueries[size_t(s)], kS, std::numeric_limits<float>::infinity(), q);
      for (int i = 0; i < kS; ++i) bins[size_t(s * stride + i)] = f.store.timeBin(q.index()[i]);
      u.push_back(f.store.time().binUnits(f.queryTimes[size_t(s)]));
    }
  }
};
SelectData& selectData() {
  static SelectData d;
  return d;
}

void BM_SelectSimd(benchmark::State& state) {
  SelectData& d = selectData();
  const int stride = SelectData::kS + photon::kSelectPadding, keep = SelectData::kS / 2;
  size_t s = 0;
  for (auto _ : state) {
    size_t j = s++ & (SelectData::kSets - 1);
    photon::TimeWindow w = photon::selectTimeWindow(d.bins.data() + j * size_t(stride), SelectData::kS, d.u[j], keep,
                                                    std::numeric_limits<float>::infinity());
    benchmark::DoNotOptimize(w);
  }
  state.SetItemsProcessed(int64_t(state.iterations()));
}
BENCHMARK(BM_SelectSimd);

// The xsimd (AVX2) kernel by name, whatever the dispatch picked: on an
// AVX-512 CPU the run then has both kinds' selection ratios.
void BM_SelectXsimd(benchmark::State& state) {
  SelectData& d = selectData();
  const int stride = SelectData::kS + photon::kSelectPadding, keep = SelectData::kS / 2;
  size_t s = 0;
  for (auto _ : state) {
    size_t j = s++ & (SelectData::kSets - 1);
    photon::TimeWindow w = photon::selectTimeWindowXsimd(d.bins.data() + j * size_t(stride), SelectData::kS, d.u[j],
                                                         keep, std::numeric_limits<float>::infinity());
    benchmark::DoNotOptimize(w);
  }
  state.SetItemsProcessed(int64_t(state.iterations()));
}
BENCHMARK(BM_SelectXsimd);

void BM_SelectQuickselect(benchmark::State& state) {
  SelectData& d = selectData();
  const int stride = SelectData::kS + photon::kSelectPadding, keep = SelectData::kS / 2;
  std::vector<float> scratch(SelectData::kS);
  Rng rng(9);
  size_t s = 0;
  for (auto _ : state) {
    size_t j = s++ & (SelectData::kSets - 1);
    photon::TimeWindow w = photon::selectTimeWindowQuickselect(d.bins.data() + j * size_t(stride), SelectData::kS,
                                                               d.u[j], keep, std::numeric_limits<float>::infinity(),
                                                               scratch.data(), rng);
    benchmark::DoNotOptimize(w);
  }
  state.SetItemsProcessed(int64_t(state.iterations()));
}
BENCHMARK(BM_SelectQuickselect);

// The baseline: float distances |t_p - t| and std::nth_element, then the
// kept count (what a float-time implementation does).
void BM_SelectNthElement(benchmark::State& state) {
  SelectData& d = selectData();
  const int stride = SelectData::kS + photon::kSelectPadding, keep = SelectData::kS / 2;
  std::vector<float> key(SelectData::kS);
  size_t s = 0;
  for (auto _ : state) {
    size_t j = s++ & (SelectData::kSets - 1);
    const uint8_t* b = d.bins.data() + j * size_t(stride);
    for (int i = 0; i < SelectData::kS; ++i) key[size_t(i)] = std::fabs(float(b[i]) + 0.5f - d.u[j]);
    std::nth_element(key.begin(), key.begin() + keep - 1, key.end());
    float lim = key[size_t(keep - 1)];
    int kept = 0;
    for (int i = 0; i < SelectData::kS; ++i) kept += std::fabs(float(b[i]) + 0.5f - d.u[j]) <= lim;
    benchmark::DoNotOptimize(kept);
  }
  state.SetItemsProcessed(int64_t(state.iterations()));
}
BENCHMARK(BM_SelectNthElement);

// ---- fixed-radius range query (progressive passes) against the k-NN ----
// Each query's radius is its own k-NN radius (k = 100 or 200), so both
// searches return the same photons: the ratio BM_Range / BM_KnnOurs at one
// k is the cost of the search itself, photons per query equal.

const std::vector<float>& knnRadii2(int k, bool morton) {
  static std::vector<float> cache[2][2];
  std::vector<float>& r = cache[k == 200][morton];
  if (r.empty()) {
    Fixture& f = fixture();
    const auto& qs = morton ? f.mortonQueries : f.randomQueries;
    photon::KnnQuery q(k);
    for (const Vec3f& p : qs) {
      f.tree.knn(p, k, std::numeric_limits<float>::infinity(), q);
      r.push_back(q.radius2);
    }
  }
  return r;
}

void BM_Range(benchmark::State& state) {
  Fixture& f = fixture();
  const auto& qs = queriesFor(state);
  const auto& r2 = knnRadii2(int(state.range(0)), state.range(1) != 0);
  photon::RangeQuery q;
  size_t i = 0;
  uint64_t found = 0;
  for (auto _ : state) {
    size_t j = i++ & (kQueries - 1);
    int n = f.tree.range(qs[j], r2[j], q);
    found += uint64_t(n);
    benchmark::DoNotOptimize(n);
  }
  state.SetItemsProcessed(int64_t(state.iterations()));
  state.counters["photons_per_query"] = double(found) / double(state.iterations());
}
BENCHMARK(BM_Range)->ArgsProduct({{100, 200}, {0, 1}})->ArgNames({"k", "morton"});

// Whole fixed-kernel estimates (estimate/fixed_kernel.h) at the k = 200
// radius: spatial (method 0) and space-time with h = 0.05 of the shutter
// (method 1), beside BM_Estimate's k-NN estimates.
void BM_FixedEstimate(benchmark::State& state) {
  Fixture& f = fixture();
  const auto& qs = queriesFor(state);
  const auto& r2 = knnRadii2(200, state.range(1) != 0);
  estimate::FixedKernelGatherer g;
  estimate::ConstantBrdf brdf{Rgb(0.3f)};
  Vec3f n(0, 1, 0);
  size_t i = 0;
  for (auto _ : state) {
    size_t j = i++ & (kQueries - 1);
    float r = std::sqrt(r2[j]);
    Rgb L = state.range(0) == 0 ? g.spatial(f.tree, qs[j], n, n, r, brdf)
                                : g.spaceTime(f.tree, qs[j], n, n, f.queryTimes[j], r, 0.05f, brdf);
    benchmark::DoNotOptimize(L);
  }
  state.SetItemsProcessed(int64_t(state.iterations()));
}
BENCHMARK(BM_FixedEstimate)->ArgsProduct({{0, 1}, {0, 1}})->ArgNames({"method", "morton"});

// ---- whole estimates: standard k = 200 vs time-dependent k_s = 200, f = 0.5 ----

void BM_Estimate(benchmark::State& state) {
  Fixture& f = fixture();
  estimate::Options o;
  o.method = estimate::Method(state.range(0));
  o.k = 200;
  o.ks = 200;
  o.fraction = 0.5f;
  const photon::KdTree& tree = o.method == estimate::Method::SpaceTime4D ? f.tree4 : f.tree;
  if (o.method == estimate::Method::SpaceTime4D) o.k = 100;
  estimate::Gatherer g(tree, o);
  const auto& qs = queriesFor(state);
  estimate::ConstantBrdf brdf{Rgb(0.3f)};
  size_t i = 0;
  Vec3f n(0, 1, 0);
  for (auto _ : state) {
    size_t j = i++ & (kQueries - 1);
    Rgb L = g.radiance(qs[j], n, n, f.queryTimes[j], brdf);
    benchmark::DoNotOptimize(L);
  }
  state.SetItemsProcessed(int64_t(state.iterations()));
}
// method: 0 standard (k=200), 1 time two-pass (k_s=200), 2 4D (k=100)
BENCHMARK(BM_Estimate)->ArgsProduct({{0, 1, 2}, {0, 1}})->ArgNames({"method", "morton"});

// ---- build ----

void BM_Build(benchmark::State& state) {
  size_t n = size_t(state.range(0));
  int threads = int(state.range(1));
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, size_t(threads));
  photon::PhotonStore src = makeSurfacePhotons(n, 4);
  double bpp = 0.0;
  for (auto _ : state) {
    state.PauseTiming();
    photon::PhotonStore s = src;
    state.ResumeTiming();
    photon::KdTree t = photon::KdTree::build(s);
    benchmark::DoNotOptimize(t);
    bpp = t.bytesPerPhoton();
  }
  state.counters["bytes_per_photon"] = bpp;
  state.counters["photons_per_s"] = benchmark::Counter(double(n) * double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Build)
    ->ArgsProduct({{1000000}, {1, 2}})
    ->ArgNames({"n", "threads"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3)
    ->UseRealTime();
BENCHMARK(BM_Build)
    ->ArgsProduct({{10000000}, {1, 2}})
    ->ArgNames({"n", "threads"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->UseRealTime();

}  // namespace
