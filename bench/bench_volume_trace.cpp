// bench/bench_volume_trace.cpp — photon tracing through media
// (photon/tracer_media.h) on scenes/fog-glass-ball.json: the volume map's
// trace (100000 stored, unaimed, the scene's max_depth 8) and the beam map
// built over it (Kind::Time, ks 64), and, for the ratio, the global map of
// the same scene (whose paths walk the same fog) and of the scene without
// its fog. Counters: stored photons per second of tracing (stored_per_s),
// emitted paths per second (paths_per_s), bytes per volume photon, and the
// volume map's trace and beam-build seconds per run (trace_s, build_s).
// Threads: TBB's default (run with taskset or -t via the environment to pin).
// Measured 2026-12-02 on the shared 2-core machine (load ~6), commit 1d1292d,
// `build/bench/tdpm_bench --benchmark_filter=FogBall`: volume map 100000
// stored in 0.112 s (895k stored/s, 165k paths/s, 5.4 stored per path),
// its Time beam build (ks 64) 1.63 s, 23 bytes per photon; global map in
// the fog 407k paths/s, without the fog 1.33M paths/s (the exterior fog
// is everywhere: paths that leave the scene scatter on until absorbed or
// max_depth).
#include <benchmark/benchmark.h>

#include <memory>
#include <string>

#include "core/progress.h"
#include "core/timer.h"
#include "photon/tracer.h"
#include "photon/volume_beam_map.h"
#include "scene/parse.h"
#include "scene/scene.h"

using namespace tdpm;

namespace {

std::unique_ptr<Scene> fogBall(bool fog) {
  scene::SceneDescription d = scene::loadScene(std::string(TDPM_SOURCE_DIR) + "/scenes/fog-glass-ball.json");
  if (!fog) {
    d.exteriorMedium = d.camera.medium = -1;
    for (auto& l : d.lights) l.medium = -1;
    for (auto& o : d.objects) o.media = {};
    d.media.clear();
  }
  return Scene::build(d);
}

// kind 0: volume map (+ beam build), 1: global map in fog, 2: global map without fog.
void BM_FogBallTrace(benchmark::State& state) {
  const int kind = int(state.range(0));
  auto s = fogBall(kind != 2);
  photon::TraceSettings ts;
  ts.kind = kind == 0 ? photon::MapKind::Volume : photon::MapKind::Global;
  ts.storedWanted = 100000;
  ts.maxBounces = 8;
  ts.seed = 1;
  double traceSeconds = 0, buildSeconds = 0, stored = 0, emitted = 0, bytes = 0;
  for (auto _ : state) {
    photon::TraceResult r = photon::tracePhotons(*s, ts, Progress{});
    traceSeconds += r.seconds;
    stored += double(r.store.size());
    emitted += double(r.emitted);
    if (kind == 0) {
      photon::BeamBuildOptions bo;
      bo.kind = photon::BeamBuildOptions::Kind::Time;
      bo.ks = 64;
      Timer t;
      photon::VolumeBeamMap m = photon::VolumeBeamMap::build(r.store, bo);
      buildSeconds += t.seconds();
      bytes = m.bytesPerPhoton();
      benchmark::DoNotOptimize(m.size());
    }
  }
  state.counters["stored_per_s"] = stored / traceSeconds;
  state.counters["paths_per_s"] = emitted / traceSeconds;
  if (kind == 0) {
    state.counters["bytes_per_photon"] = bytes;
    state.counters["build_s"] = buildSeconds / double(state.iterations());
    state.counters["trace_s"] = traceSeconds / double(state.iterations());
  }
}
BENCHMARK(BM_FogBallTrace)->Arg(0)->Arg(1)->Arg(2)->ArgName("map")->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();

}  // namespace
