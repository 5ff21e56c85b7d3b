// bench/bench_volume.cpp — the volume estimates (estimate/volume_estimators.h)
// at equal error: the beam estimate against the ray-marched point estimate on
// the same synthetic volume photons of known density (uniform in [0, 1]^3 and
// in the shutter, isotropic, a homogeneous medium sigma_t = 0.8), one thread.
// Each benchmark reports its time per segment and, as counters, the RMS
// relative error of its estimates against the known truth over the fixed
// segments (rms_err) and the beam map's bytes per photon. Equal error:
// the march's step count (and k_s) whose rms_err first reaches the beam's
// (bench/README.md "Volume estimates").
#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <memory>
#include <vector>

#include "core/rng.h"
#include "estimate/volume_estimators.h"
#include "photon/store.h"
#include "photon/volume_beam_map.h"

using namespace tdpm;
using namespace tdpm::estimate;

namespace {

constexpr float kSigmaT = 0.8f;
constexpr int kPhotons = 200000;
constexpr int kSegments = 512;

// kind 0: uniform in [0, 1]^3. kind 1, a volumetric caustic: half the
// photons in a thin cylinder (radius kCausticR about the line x = y = 0.5,
// the energy of a focused beam), half uniform; segments cross the cylinder.
constexpr float kCausticR = 0.02f;
struct VolumeData {
  photon::PhotonStore store{0.0f, 1.0f};
  photon::VolumeBeamMap map;
  std::vector<Segment> segs;
  std::vector<double> truth;
  VolumeData(int kind, int beamK) {
    Rng rng(1);
    store.reserve(kPhotons);
    for (int i = 0; i < kPhotons; ++i) {
      Vec3f p(rng.uniform(), rng.uniform(), rng.uniform());
      if (kind == 1 && (i & 1)) {
        float a = 2.0f * kPi * rng.uniform(), r = kCausticR * std::sqrt(rng.uniform());
        p = Vec3f(0.5f + r * std::cos(a), 0.5f + r * std::sin(a), p.z);
      }
      float z = 1.0f - 2.0f * rng.uniform(), phi = 2.0f * kPi * rng.uniform();
      float s = std::sqrt(std::max(0.0f, 1.0f - z * z));
      store.add(p, Rgb(1.0f / kPhotons), Vec3f(s * std::cos(phi), s * std::sin(phi), z), rng.uniform());
    }
    store.shrinkToFit();
    photon::BeamBuildOptions bo;
    bo.ks = beamK;
    map = photon::VolumeBeamMap::build(store, bo);
    const double k4 = media::kInv4Pi, rhoU = kind == 1 ? 0.5 : 1.0;
    const double rhoC = kind == 1 ? 0.5 / (kPi * kCausticR * kCausticR) : 0.0;
    while (int(segs.size()) < kSegments) {
      Vec3f a(0.2f + 0.6f * rng.uniform(), 0.2f + 0.6f * rng.uniform(), 0.2f + 0.6f * rng.uniform());
      Vec3f b(0.2f + 0.6f * rng.uniform(), 0.2f + 0.6f * rng.uniform(), 0.2f + 0.6f * rng.uniform());
      if (kind == 1) a.x = 0.2f, b.x = 0.8f, a.y = 0.48f + 0.04f * rng.uniform(), b.y = 1.0f - a.y;
      float len = length(b - a);
      if (len < 0.3f) continue;
      Segment seg{a, (b - a) * (1.0f / len), 0.0f, len};
      double L = rhoU * (1.0 - std::exp(-kSigmaT * len)) / kSigmaT;
      if (kind == 1) {  // the chord through the cylinder: |xy(s) - (0.5, 0.5)| < R
        double ox = a.x - 0.5, oy = a.y - 0.5, dx = seg.d.x, dy = seg.d.y;
        double A = dx * dx + dy * dy, B = 2 * (ox * dx + oy * dy), C = ox * ox + oy * oy - kCausticR * kCausticR;
        double disc = B * B - 4 * A * C;
        if (disc > 0) {
          double s0 = (-B - std::sqrt(disc)) / (2 * A), s1 = (-B + std::sqrt(disc)) / (2 * A);
          L += rhoC * (std::exp(-kSigmaT * s0) - std::exp(-kSigmaT * s1)) / kSigmaT;
        }
      }
      segs.push_back(seg);
      truth.push_back(k4 * L);
    }
  }
};

const VolumeData& data(int kind, int beamK) {
  static std::map<std::pair<int, int>, std::unique_ptr<VolumeData>> cache;
  auto& d = cache[{kind, beamK}];
  if (!d) d = std::make_unique<VolumeData>(kind, beamK);
  return *d;
}

// RMS relative error of estimate(seg) over the segments, at times 0.1 ... 0.9.
template <class F>
double rmsError(const VolumeData& d, F&& estimate) {
  double e2 = 0.0;
  for (size_t i = 0; i < d.segs.size(); ++i) {
    float t = 0.1f + 0.8f * float(i % 9) / 8.0f;
    double r = estimate(d.segs[i], t) / d.truth[i] - 1.0;
    e2 += r * r;
  }
  return std::sqrt(e2 / double(d.segs.size()));
}

void BM_VolumeBeam(benchmark::State& state) {
  const VolumeData& d = data(int(state.range(0)), int(state.range(1)));
  photon::BeamQuery q;
  auto est = [&](const Segment& seg, float t) {
    return double(beamRadiance(d.map, q, seg, t, HgPhase{0.0f}, HomogeneousTransmittance{Rgb(kSigmaT), seg.s0}).g);
  };
  state.counters["rms_err"] = rmsError(d, est);
  state.counters["bytes_per_photon"] = d.map.bytesPerPhoton();
  size_t i = 0;
  for (auto _ : state) {
    const Segment& seg = d.segs[i++ % d.segs.size()];
    benchmark::DoNotOptimize(est(seg, 0.5f));
  }
}
BENCHMARK(BM_VolumeBeam)->ArgsProduct({{0, 1}, {64, 200}})->ArgNames({"caustic", "k"});

void BM_VolumeMarch(benchmark::State& state) {
  const VolumeData& d = data(int(state.range(0)), 64);
  const int steps = int(state.range(1));
  VolumeOptions o;
  o.ks = int(state.range(2));
  VolumeGatherer g(d.map.tree(), o);
  Rng rng(2);
  auto est = [&](const Segment& seg, float t) {
    return double(g.march(seg, t, HgPhase{0.0f}, HomogeneousTransmittance{Rgb(kSigmaT), seg.s0}, steps, rng).g);
  };
  state.counters["rms_err"] = rmsError(d, est);
  size_t i = 0;
  for (auto _ : state) {
    const Segment& seg = d.segs[i++ % d.segs.size()];
    benchmark::DoNotOptimize(est(seg, 0.5f));
  }
}
BENCHMARK(BM_VolumeMarch)
    ->ArgsProduct({{0, 1}, {8, 16, 32, 64, 128, 256, 512}, {100, 200}})
    ->ArgNames({"caustic", "steps", "ks"});

}  // namespace
