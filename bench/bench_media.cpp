// bench/bench_media.cpp — grid tracking (media/medium.h) with the 16^3
// majorant grid against one global majorant (`cells` 1, the first version's
// tracking) on a sparse smoke blob: ratio-tracking transmittance and
// delta-tracking free flight along fixed random rays through the grid's
// box, one thread. Time per ray; the counter `mean` (mean transmittance, or
// the share of flights that collide) must agree between the two within
// noise: the same estimator, fewer null collisions (bench/README.md, "Media").
// `dense:1`: the worst case for the majorant grid, a uniform grid (density 1
// everywhere, sigma_t 4.5): no cell is below the global bound, so the DDA's
// cell steps are pure overhead.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "core/rng.h"
#include "media/medium.h"

using namespace tdpm;

namespace {

// 64^3 cells on [0, 1]^3: a soft blob (radius 0.15, peak 8) off-centre and a
// thin haze band (0.05) along the bottom, zero elsewhere: the shape of
// bench/media/smoke_blob.py's scene. sigma_t = 4.5 per density, grey.
scene::MediumDesc blob(bool dense) {
  scene::MediumDesc d;
  d.type = scene::MediumDesc::Type::Grid;
  d.sigmaA = Rgb(0.5f);
  d.sigmaS = Rgb(4.0f);
  const int n = 64;
  d.grid.nx = d.grid.ny = d.grid.nz = n;
  d.grid.density.resize(size_t(n) * n * n);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        float px = (x + 0.5f) / n - 0.3f, py = (y + 0.5f) / n - 0.62f, pz = (z + 0.5f) / n - 0.35f;
        float d2 = (px * px + py * py + pz * pz) / (0.15f * 0.15f);
        float v = d2 < 4.0f ? 8.0f * std::exp(-2.0f * d2) : 0.0f;
        if ((y + 0.5f) / n < 0.08f) v += 0.05f;
        if (dense) v = 1.0f;
        d.grid.density[(size_t(z) * n + size_t(y)) * n + size_t(x)] = v;
      }
  d.grid.bounds = {{0, 0, 0}, {1, 1, 1}};
  return d;
}

struct Rays {
  std::vector<Vec3f> o, d;
  Rays() {
    Rng rng(3);
    for (int i = 0; i < 4096; ++i) {  // between random points on two faces of a box around the grid
      Vec3f a(-0.2f + 1.4f * rng.uniform(), -0.2f + 1.4f * rng.uniform(), -0.2f);
      Vec3f b(-0.2f + 1.4f * rng.uniform(), -0.2f + 1.4f * rng.uniform(), 1.2f);
      o.push_back(a);
      d.push_back(normalize(b - a));
    }
  }
};

void BM_GridTransmittance(benchmark::State& state) {
  static const scene::MediumDesc descs[2] = {blob(false), blob(true)};
  static const Rays rays;
  const media::Medium m = media::makeMedium(descs[state.range(1)], nullptr, nullptr, int(state.range(0)));
  Rng rng(5);
  double sum = 0;
  size_t n = 0;
  for (auto _ : state) {
    size_t i = n++ % rays.o.size();
    Rgb T = media::transmittance(m, rays.o[i], rays.d[i], 3.0f, 0.5f, rng);
    sum += T.r;
    benchmark::DoNotOptimize(T);
  }
  state.counters["mean"] = sum / double(n);
}

void BM_GridFreeFlight(benchmark::State& state) {
  static const scene::MediumDesc descs[2] = {blob(false), blob(true)};
  static const Rays rays;
  const media::Medium m = media::makeMedium(descs[state.range(1)], nullptr, nullptr, int(state.range(0)));
  Rng rng(6);
  double hits = 0;
  size_t n = 0;
  for (auto _ : state) {
    size_t i = n++ % rays.o.size();
    Rgb beta(1.0f);
    media::FreeFlight f = media::sampleFreeFlight(m, rays.o[i], rays.d[i], 3.0f, 0.5f, rng, beta);
    hits += f.event != media::FreeFlight::Event::Escape;
    benchmark::DoNotOptimize(f);
  }
  state.counters["mean"] = hits / double(n);
}

}  // namespace

BENCHMARK(BM_GridTransmittance)->ArgNames({"cells", "dense"})->ArgsProduct({{1, 16}, {0, 1}});
BENCHMARK(BM_GridFreeFlight)->ArgNames({"cells", "dense"})->ArgsProduct({{1, 16}, {0, 1}});
