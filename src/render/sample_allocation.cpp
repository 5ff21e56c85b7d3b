// render/sample_allocation.cpp — the eye-only pilot and the per-pixel
// sample counts of progressive passes (render/sample_allocation.h).
#include "render/sample_allocation.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/rng.h"
#include "render/camera_sample.h"
#include "render/film.h"
#include "render/pixel_loop.h"
#include "render/photon_integrator.h"
#include "render/pixel_share.h"
#include "render/tile_loop.h"
#include "sampling/sampler.h"

namespace tdpm {

namespace {

// The pilot's own sequence: no pass ever draws from it.
constexpr uint64_t kPilotSeedSalt = 0x9170e7e5ull;

struct PilotScratch {
  PhotonIntegrator::ThreadState state;
};

// The pilot's per-pixel luminance mean and variance -> each pixel's noise.
std::vector<float> noiseFromPilot(std::vector<float> mean, std::vector<float> var, int w, int h) {
  const size_t n = size_t(w) * size_t(h);
  double total = 0;
  for (float m : mean) total += double(m);
  const double floor = std::max(kNoiseFloorFraction * total / double(std::max<size_t>(n, 1)), 1e-30);
  // A rare bright path found by one pilot sample of one pixel stands for
  // those its neighbours missed (a motion-blurred highlight runs across
  // pixels): first the 3x3 neighbourhood's mean variance over its mean
  // value, then the largest of that within kDilation pixels.
  // (Transients are freed as soon as they are used: at most 12 bytes a
  // pixel at once besides the progressive state, within what the memory
  // pre-flight charges for a render's sampler, render/memory_budget.h.)
  std::vector<float> local(n, 0.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double v = 0, m = 0;
      int k = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          int xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
          size_t j = size_t(yy) * size_t(w) + size_t(xx);
          v += double(var[j]);
          m += double(mean[j]);
          ++k;
        }
      local[size_t(y) * size_t(w) + size_t(x)] = float(std::sqrt(v / k) / (m / k + floor));
    }
  std::vector<float>().swap(mean);
  std::vector<float>().swap(var);
  // Separable max filter: rows, then columns.
  std::vector<float> rows(n, 0.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float best = 0.0f;
      for (int xx = std::max(0, x - kDilation); xx <= std::min(w - 1, x + kDilation); ++xx)
        best = std::max(best, local[size_t(y) * size_t(w) + size_t(xx)]);
      rows[size_t(y) * size_t(w) + size_t(x)] = best;
    }
  std::vector<float>().swap(local);
  std::vector<float> noise(n, 0.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float best = 0.0f;
      for (int yy = std::max(0, y - kDilation); yy <= std::min(h - 1, y + kDilation); ++yy)
        best = std::max(best, rows[size_t(yy) * size_t(w) + size_t(x)]);
      noise[size_t(y) * size_t(w) + size_t(x)] = best;
    }
  return noise;
}

}  // namespace

std::vector<float> pilotNoise(const Scene& scene, const RenderOptions& opt, const Progress& progress,
                              dist::Comm& comm) {
  const int w = scene.camera.width(), h = scene.camera.height();
  const size_t n = size_t(w) * size_t(h);
  // No maps and no final gather: emission through specular chains and
  // direct light (light sampling at full weight), the eye side alone.
  PhotonIntegratorSettings is;
  is.timeDependent = false;
  is.gatherRays = 0;
  is.maxDepth = opt.maxDepth;
  PhotonIntegrator eyeOnly(scene, {}, is);
  CameraSamplePlan plan{pixelFilterFor(opt), {}};
  plan.times.moving = scene.hasMotion;
  setFrameTimes(plan.times, scene.shutter, opt.frameOpen, opt.frameClose);  // an animation frame's passes
  const uint64_t seed = hashCombine(opt.seed, kPilotSeedSalt);
  std::vector<float> mean(n, 0.0f), var(n, 0.0f);
  forEachTile<PilotScratch>(w, h, "pilot", progress, [&](const Tile& t, PilotScratch& s) {
    double sum = 0, sq = 0;  // the pixel in flight's luminance sums
    samplePixels<SobolPixelSampler>(
        t, w, scene.camera, plan, seed,
        [&](size_t, uint32_t& f, uint32_t& c) {
          f = 0;
          c = uint32_t(kPilotSamples);
          sum = sq = 0;
          return true;
        },
        [&](size_t, uint32_t, const CameraRay& ray, SobolStream& stream) {
          Rgb L = saturateSample(eyeOnly.radiance(ray.origin, ray.direction, ray.time01, stream, s.state));
          double l = std::min(double(L.luminance()), 1e30);
          sum += l;
          sq += l * l;
        },
        [&](size_t idx) {
          double m = sum / kPilotSamples;
          mean[idx] = float(m);
          var[idx] = float(std::max(0.0, (sq - sum * m) / (kPilotSamples - 1)));
        });
  }, tileShareOf(comm));
  sharePixels(comm, w, h, mean, true);
  sharePixels(comm, w, h, var, true);
  return noiseFromPilot(std::move(mean), std::move(var), w, h);
}

std::vector<uint32_t> allocatePassSamples(const std::vector<float>& noise, int spp, int cap, double budget) {
  const size_t n = noise.size();
  const uint32_t lo = uint32_t(spp);
  std::vector<uint32_t> m(n, lo);
  if (!(budget > 0) || cap <= 1 || n == 0) return m;
  const double hi = double(spp) * double(cap);
  const double allowed = budget * double(spp) * double(n);
  auto samples = [&](double c, size_t i) {
    double v = std::isfinite(noise[i]) ? double(noise[i]) : 0.0;
    return std::clamp(std::ceil(c * v), double(lo), hi);
  };
  auto extra = [&](double c) {
    double e = 0;
    for (size_t i = 0; i < n; ++i) e += samples(c, i) - double(lo);
    return e;
  };
  // The largest c whose extra samples fit: bracket, then bisect (serial,
  // doubles, fixed order: the same c on every machine and rank).
  double most = 0, smallest = HUGE_VAL;
  for (float v : noise)
    if (std::isfinite(v) && v > 0) {
      most += hi - double(lo);
      smallest = std::min(smallest, double(v));
    }
  double cLo = 0, cHi = 1;
  if (most <= allowed) {
    cLo = hi / smallest;  // every noisy pixel at the cap fits the budget
  } else {
    while (extra(cHi) <= allowed) {
      cLo = cHi;
      cHi *= 2;
    }
    for (int it = 0; it < 100 && cHi - cLo > 1e-9 * cHi; ++it) {
      double mid = 0.5 * (cLo + cHi);
      (extra(mid) <= allowed ? cLo : cHi) = mid;
    }
  }
  for (size_t i = 0; i < n; ++i) m[i] = uint32_t(samples(cLo, i));
  return m;
}

std::vector<uint32_t> passSampleCounts(const Scene& scene, const RenderOptions& opt, const Progress& progress,
                                       dist::Comm& comm) {
  if (!(opt.passExtraSamples > 0) || opt.passSampleCap <= 1) return {};
  return allocatePassSamples(pilotNoise(scene, opt, progress, comm), opt.spp, opt.passSampleCap,
                             double(opt.passExtraSamples));
}

}  // namespace tdpm
