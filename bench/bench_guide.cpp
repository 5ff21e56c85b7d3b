// bench/bench_guide.cpp — what the path tracer's caustic guide costs per
// camera sample (render/caustic_guide.h), as one ratio measured inside one
// benchmark: guided and unguided path tracing of the same pixels and sample
// indices, interleaved in small chunks on one thread, each timed by the
// thread's CPU clock. On a shared machine, whole 1024-spp renders of either
// kind run side by side differed by 10-20% from round to round
// (docs/sampling.md, "Caustic guiding"); chunks of a few milliseconds,
// alternating which goes first, see the same machine. bench/ratios.py reads
// the two totals (t_guided, t_unguided) as the ratio
// pathtrace_guided_over_unguided. The guide's build is reported apart
// (guide_build_s): a render pays it once, ~1 s for 1024 spp here.
#include <benchmark/benchmark.h>

#include <time.h>

#include <memory>
#include <string>

#include "render/caustic_guide.h"
#include "render/path_tracer.h"
#include "sampling/sampler.h"
#include "scene/parse.h"
#include "scene/scene.h"

using namespace tdpm;

namespace {

double threadCpuSeconds() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// cube-caustic at 160x120 with the guide a 1024-spp render builds (one
// photon per 100 camera samples: 196,608), the issue-9 target's setting.
void BM_GuidedPathTrace(benchmark::State& state) {
  scene::SceneDescription d = scene::loadScene(std::string(TDPM_SOURCE_DIR) + "/scenes/cube-caustic.json");
  d.camera.width = 160;
  d.camera.height = 120;
  auto scene = Scene::build(d);
  const int width = 160, height = 120, maxDepth = 16;
  CausticGuideSettings gs;
  gs.fraction = 0.5f;
  gs.photons = size_t(width) * size_t(height) * 1024 / 100;
  gs.seed = 1;
  double t0 = threadCpuSeconds();
  CausticGuide guide = CausticGuide::build(*scene, gs, Progress{});
  double buildSeconds = threadCpuSeconds() - t0;  // this thread's share (the build is parallel)
  PathTracer guided(*scene, maxDepth, &guide), plain(*scene, maxDepth, nullptr);
  PathTracer::ThreadState ts;
  const uint64_t seed = 1;
  // As a render orders them: pixel after pixel (row-major, as one thread
  // walks a row of tiles), each pixel's samples one after another (a
  // fixed-spp render takes them in one batch), so the first vertices of a
  // pixel's samples stay in cache, and the second ones do not.
  const int pixelsPerChunk = 8, spp = 256;
  size_t pixel = 0;
  double tGuided = 0, tPlain = 0;
  uint64_t samples = 0;
  Rgb sink(0.0f);
  auto chunk = [&](const PathTracer& pt) {
    double start = threadCpuSeconds();
    for (size_t idx = pixel; idx < pixel + size_t(pixelsPerChunk); ++idx) {
      int x = int(idx % size_t(width)), y = int(idx / size_t(width));
      SobolPixelSampler ps(seed, idx);
      for (uint32_t i = 0; i < uint32_t(spp); ++i) {
        CameraSample cs = ps.camera(i);
        Vec3f o, dir;
        scene->camera.generateRay({float(x) + cs.pixelOffset.x, float(y) + cs.pixelOffset.y}, cs.time01, o, dir);
        SobolStream stream = ps.stream(i);
        sink += pt.radiance(o, dir, cs.time01, stream, ts);
      }
    }
    return threadCpuSeconds() - start;
  };
  bool guidedFirst = true;
  for (auto _ : state) {
    if (guidedFirst) {
      tGuided += chunk(guided);
      tPlain += chunk(plain);
    } else {
      tPlain += chunk(plain);
      tGuided += chunk(guided);
    }
    guidedFirst = !guidedFirst;
    samples += uint64_t(pixelsPerChunk) * uint64_t(spp);
    pixel = (pixel + size_t(pixelsPerChunk)) % (size_t(width) * size_t(height));
  }
  benchmark::DoNotOptimize(sink);
  state.counters["t_guided"] = tGuided;
  state.counters["t_unguided"] = tPlain;
  state.counters["guided_over_unguided"] = tPlain > 0 ? tGuided / tPlain : 0.0;
  state.counters["ns_per_sample_unguided"] = samples ? 1e9 * tPlain / double(samples) : 0.0;
  state.counters["guide_build_s"] = buildSeconds;
  state.counters["cache_filled"] = double(guide.cacheFilled());
  state.counters["cache_subcells"] = double(guide.cacheEntries());
}
// 2400 chunk pairs: every pixel once at 256 spp, 4.9M samples of each
// kind, ~20 s. The cache's lists are filled as a render fills them, at
// first use, here amortised over 256 samples a pixel instead of 1024.
BENCHMARK(BM_GuidedPathTrace)->Unit(benchmark::kMillisecond)->Iterations(2400);

}  // namespace
