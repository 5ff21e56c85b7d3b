// bench/bench_render.cpp — end-to-end figures on the paper's scenes, each a
// ratio against something measured in the same run (bench/check turns the
// JSON into ratios):
//  * raw Embree incoherent rays/s on a scene vs our photon tracing's rays/s
//    on the same scene (tracing overhead);
//  * whole renders (photon passes + tile loop) per method at fixed budgets:
//    time vs standard, accumulation vs time, 2 threads vs 1.
#include <benchmark/benchmark.h>

#include <memory>
#include <string>
#include <vector>

#include "core/rng.h"
#include "photon/tracer.h"
#include "render/renderer.h"
#include "render/threads.h"
#include "sampling/warp.h"
#include "scene/parse.h"
#include "scene/scene.h"

using namespace tdpm;

namespace {

struct BenchScene {
  std::string file;
  int width, height;
};

const BenchScene kScenes[] = {
    {"cube-caustic.json", 160, 120},
    {"truck-laser.json", 160, 90},
    {"glass-ball.json", 160, 90},
};

std::unique_ptr<Scene> loadBenchScene(int which) {
  scene::SceneDescription d = scene::loadScene(std::string(TDPM_SOURCE_DIR) + "/scenes/" + kScenes[which].file);
  d.camera.width = kScenes[which].width;
  d.camera.height = kScenes[which].height;
  return Scene::build(d);
}

// ---- raw Embree: incoherent rays (random origins in the scene's bounds,
// uniform directions, random times), no shading, one thread ----
void BM_EmbreeIncoherent(benchmark::State& state) {
  auto s = loadBenchScene(int(state.range(0)));
  state.SetLabel(kScenes[state.range(0)].file);
  const size_t n = 1 << 18;
  std::vector<Vec3f> o(n), d(n);
  std::vector<float> t(n);
  Rng rng(9);
  Bounds3f b = s->bounds;
  for (size_t i = 0; i < n; ++i) {
    o[i] = b.lo + b.diagonal() * Vec3f(rng.uniform(), rng.uniform(), rng.uniform());
    d[i] = squareToUniformSphere({rng.uniform(), rng.uniform()});
    t[i] = rng.uniform();
  }
  uint64_t hits = 0;
  for (auto _ : state) {
    for (size_t i = 0; i < n; ++i) {
      RawHit h;
      hits += s->embree().intersect(o[i], d[i], 1e30f, t[i], h);
    }
  }
  benchmark::DoNotOptimize(hits);
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(n));
  state.counters["rays_per_s"] = benchmark::Counter(double(state.iterations()) * double(n), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_EmbreeIncoherent)->Arg(0)->Arg(1)->ArgName("scene")->Unit(benchmark::kMillisecond);

// ---- photon tracing (caustic + global maps), one thread ----
void BM_PhotonTrace(benchmark::State& state) {
  auto s = loadBenchScene(int(state.range(0)));
  state.SetLabel(kScenes[state.range(0)].file);
  ThreadLimit one(1);
  uint64_t rays = 0;
  for (auto _ : state) {
    for (photon::MapKind kind : {photon::MapKind::Caustic, photon::MapKind::Global}) {
      photon::TraceSettings ts;
      ts.kind = kind;
      ts.storedWanted = kind == photon::MapKind::Caustic ? 50000 : 20000;
      photon::TraceResult r = photon::tracePhotons(*s, ts, Progress{});
      rays += r.rays;
    }
  }
  state.counters["rays_per_s"] = benchmark::Counter(double(rays), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PhotonTrace)->Arg(0)->Arg(1)->ArgName("scene")->Unit(benchmark::kMillisecond);

// ---- whole renders at fixed budgets ----
const char* const kMethodNames[] = {"time", "standard", "accumulation", "pathtrace"};

void BM_Render(benchmark::State& state) {
  int which = int(state.range(0));
  const char* method = kMethodNames[state.range(1)];
  int threads = int(state.range(2));
  auto s = loadBenchScene(which);
  state.SetLabel(std::string(kScenes[which].file) + " " + method + " " + std::to_string(threads) + "t");
  ThreadLimit limit(threads);
  RenderOptions o;
  o.method = *parseRenderMethod(method);
  o.spp = 4;
  o.seed = 3;
  // Budgets of the paper, scaled down: cube 900k caustic photons / 20
  // frames there; truck 40k / 9 frames.
  o.causticPhotons = which == 1 ? 40000 : 200000;
  o.globalPhotons = 20000;
  o.frames = which == 1 ? 9 : 20;
  o.estimate.k = 100;
  o.estimate.ks = 100;
  for (auto _ : state) {
    RenderStats st;
    Film f = render(*s, o, Progress{}, st);
    benchmark::DoNotOptimize(f.color.data());
  }
}
BENCHMARK(BM_Render)
    ->Args({0, 0, 1})->Args({0, 0, 2})  // cube: time, 1 and 2 threads
    ->Args({0, 1, 2})                   // cube: standard
    ->Args({0, 2, 2})                   // cube: accumulation
    ->Args({1, 0, 2})->Args({1, 1, 2})->Args({1, 2, 2})  // truck: time, standard, accumulation
    ->ArgNames({"scene", "method", "threads"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

}  // namespace
