// photon/tracer.cpp — photon paths: light choice, emission, bounces with
// Russian roulette, storage, and the pilot run that sizes the emission.
#include "photon/tracer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <vector>

#include "core/rng.h"
#include "core/timer.h"
#include "scene/bsdf.h"

namespace tdpm::photon {

namespace {

constexpr uint32_t kPathsPerBatch = 1024;
constexpr uint32_t kPilotBatches = 16;
// A scene that stores (almost) nothing must not hang: the pilot gives up
// after kMaxPilotPaths paths, and the emission is capped at
// kMaxPathsPerPhoton paths per wanted photon (both reported as warnings).
constexpr uint64_t kMaxPilotPaths = uint64_t(1) << 22;
constexpr double kMaxPathsPerPhoton = 1000.0;

// Radical inverse in base 2 with a random XOR scramble: a (0,1)-sequence,
// so every prefix of the path times is stratified over the shutter.
float scrambledVanDerCorput(uint32_t i, uint32_t scramble) {
  uint32_t bits = i;
  bits = (bits << 16) | (bits >> 16);
  bits = ((bits & 0x00ff00ffu) << 8) | ((bits & 0xff00ff00u) >> 8);
  bits = ((bits & 0x0f0f0f0fu) << 4) | ((bits & 0xf0f0f0f0u) >> 4);
  bits = ((bits & 0x33333333u) << 2) | ((bits & 0xccccccccu) >> 2);
  bits = ((bits & 0x55555555u) << 1) | ((bits & 0xaaaaaaaau) >> 1);
  bits ^= scramble;
  return std::min(float(bits >> 8) * 0x1p-24f, 0x1.fffffep-1f);
}

struct LightTable {
  std::vector<float> cdf;  // over lights, by emitted power (luminance)
  std::vector<float> pdf;
  bool empty() const { return cdf.empty(); }
  uint32_t pick(float u) const {
    auto it = std::upper_bound(cdf.begin(), cdf.end(), u);
    return uint32_t(std::min<size_t>(size_t(it - cdf.begin()), cdf.size() - 1));
  }
};

LightTable makeLightTable(const Scene& scene) {
  LightTable t;
  double total = 0;
  std::vector<double> w;
  for (const Light& l : scene.lights) {
    double p = std::max(0.0f, emittedPower(l, scene.bounds).average());
    w.push_back(p);
    total += p;
  }
  if (!(total > 0)) return t;
  double acc = 0;
  for (double p : w) {
    acc += p;
    t.cdf.push_back(float(acc / total));
    t.pdf.push_back(float(p / total));
  }
  t.cdf.back() = 1.0f;
  return t;
}

struct Tracer {
  const Scene& scene;
  const TraceSettings& settings;
  LightTable lights;
  float t0, t1, ts;
  uint32_t timeScramble;

  // Traces paths [first, first + count) of batch `b` into `out`, energies
  // scaled by `energyScale` (= ts / n_e). Returns nothing: out grows.
  void traceBatch(uint64_t b, double energyScale, PhotonStore& out) const {
    Rng rng(hashCombine(settings.seed, uint64_t(settings.kind) + 1, b), 0x9e37);
    for (uint32_t i = 0; i < kPathsPerBatch; ++i) {
      uint64_t g = b * kPathsPerBatch + i;
      float time01 = settings.spreadInTime ? scrambledVanDerCorput(uint32_t(g), timeScramble) : settings.fixedTime01;
      tracePath(time01, rng, energyScale, out);
    }
  }

  void tracePath(float time01, Rng& rng, double energyScale, PhotonStore& out) const {
    uint32_t li = lights.pick(rng.uniform());
    const Light& light = scene.lights[li];
    EmittedRay ray;
    Vec2f uPos{rng.uniform(), rng.uniform()}, uDir{rng.uniform(), rng.uniform()};
    if (!emitFromLight(light, time01, scene.bounds, uPos, uDir, ray)) return;
    Rgb power = ray.flux / lights.pdf[li];
    float time = scene.shutter.instant() ? t0 : scene.shutter.fromNormalized(time01);
    // Off the emitter's surface: an area light is geometry, and a photon
    // starting on it would hit it at distance zero.
    Vec3f origin = scene.spawnOrigin(ray.origin, ray.direction, ray.direction), dir = ray.direction;
    bool allSpecular = true;  // every bounce so far was a delta reflection/refraction
    for (int bounce = 0; bounce <= settings.maxBounces; ++bounce) {
      Hit hit;
      if (!scene.intersect(origin, dir, std::numeric_limits<float>::infinity(), time01, hit)) return;
      if (hit.isLight()) return;  // emitters absorb
      const Material& mat = scene.materials[scene.objects[hit.object].material];
      if (!mat.isDeltaOnly()) {
        bool store = settings.kind == MapKind::Global || (bounce > 0 && allSpecular);
        if (store) out.add(hit.p, power * float(energyScale), -dir, time);
        if (settings.kind == MapKind::Caustic) return;  // L S+ D ends here
      }
      ShadingContext ctx = makeShadingContext(mat, mat.albedo.at(hit.localP), hit.n, -dir);
      BsdfSample bs;
      Vec2f u{rng.uniform(), rng.uniform()};
      if (!bsdfSample(ctx, u, rng.uniform(), Transport::Importance, bs)) return;
      if (settings.kind == MapKind::Caustic && !bs.delta) return;
      allSpecular = allSpecular && bs.delta;
      // Russian roulette by the scattering's throughput: surviving photons
      // keep (on average) their power instead of dimming.
      float survive = std::min(1.0f, bs.weight.maxComponent());
      if (!(survive > 0) || rng.uniform() >= survive) return;
      power = power * bs.weight / survive;
      origin = scene.spawnOrigin(hit.p, hit.n, bs.wi);
      dir = bs.wi;
    }
  }

  // Traces batches [0, batches) in parallel into one store, batch order.
  PhotonStore traceBatches(uint64_t batches, double energyScale, const Progress& progress, const char* stage) const {
    std::vector<PhotonStore> parts(size_t(batches), PhotonStore(t0, t1));
    std::atomic<size_t> done{0};
    progress(stage, 0, size_t(batches));
    tbb::parallel_for(tbb::blocked_range<size_t>(0, size_t(batches), 1), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t b = r.begin(); b != r.end(); ++b) {
        traceBatch(b, energyScale, parts[b]);
        progress(stage, done.fetch_add(1) + 1, size_t(batches));
      }
    });
    PhotonStore all(t0, t1);
    all.appendBatches(parts);
    return all;
  }
};

}  // namespace

void photonTimeRange(const Scene& scene, float& t0, float& t1) {
  t0 = scene.shutter.open;
  t1 = scene.shutter.instant() ? scene.shutter.open + 1.0f : scene.shutter.close;
}

bool sceneHasSpecular(const Scene& scene) {
  for (const SceneObject& o : scene.objects)
    if (scene.materials[o.material].isDeltaOnly()) return true;
  return false;
}

TraceResult tracePhotons(const Scene& scene, const TraceSettings& settings, const Progress& progress) {
  Timer timer;
  TraceResult result;
  float t0, t1;
  photonTimeRange(scene, t0, t1);
  result.store = PhotonStore(t0, t1);
  Tracer tracer{scene, settings, makeLightTable(scene), t0, t1, t1 - t0,
                uint32_t(mix64(settings.seed ^ 0x7173ull))};
  if (settings.storedWanted == 0 || tracer.lights.empty()) return result;
  if (settings.kind == MapKind::Caustic && !sceneHasSpecular(scene)) return result;
  const char* stage = settings.kind == MapKind::Caustic ? "caustic photons" : "global photons";

  // Pilot: how many photons does a path store on average? Grow the pilot
  // until something is stored or the cap says the scene stores nothing.
  uint64_t pilotBatches = kPilotBatches;
  size_t stored = 0;
  for (;;) {
    PhotonStore pilot = tracer.traceBatches(pilotBatches, 1.0, Progress{}, stage);
    stored = pilot.size();
    uint64_t paths = pilotBatches * kPathsPerBatch;
    if (stored > 0 || paths >= kMaxPilotPaths) break;
    pilotBatches *= 8;
  }
  if (stored == 0) {
    result.warning = std::string(stage) + ": none of " + std::to_string(pilotBatches * kPathsPerBatch) +
                     " paths stored a photon; the map is empty";
    return result;
  }
  double perPath = double(stored) / double(pilotBatches * kPathsPerBatch);
  double pathsNeeded = double(settings.storedWanted) / perPath;
  double pathsCap = kMaxPathsPerPhoton * double(settings.storedWanted);
  if (pathsNeeded > pathsCap) {
    pathsNeeded = pathsCap;
    result.warning = std::string(stage) + ": only " + std::to_string(perPath * 100.0).substr(0, 6) +
                     "% of paths store a photon; emission capped at " + std::to_string(uint64_t(pathsCap)) + " paths";
  }
  uint64_t batches = std::max<uint64_t>(1, uint64_t(std::ceil(pathsNeeded / kPathsPerBatch)));

  result.emitted = batches * kPathsPerBatch;
  // Q = flux * ts / n_e (method.md section 2).
  double energyScale = double(tracer.ts) / double(result.emitted);
  result.store = tracer.traceBatches(batches, energyScale, progress, stage);
  result.store.shrinkToFit();
  result.seconds = timer.seconds();
  return result;
}

}  // namespace tdpm::photon
