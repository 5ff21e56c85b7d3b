// render/renderer.cpp — per-pixel sampling over the tile loop.
#include "render/renderer.h"

#include <cstring>
#include <vector>

#include "core/error.h"
#include "core/rng.h"
#include "core/timer.h"
#include "render/path_tracer.h"
#include "render/tile_loop.h"
#include "sampling/stratified.h"

namespace tdpm {

namespace {

const char* const kMethods[] = {"pathtrace", "static", "accumulation", "standard", "time", nullptr};

struct PixelScratch {
  std::vector<CameraSample> samples;
  std::vector<uint32_t> strata;
};

// Streams the samples of one pixel into a mean and the variance of that
// mean (Welford's update: stable in one pass).
struct PixelAccumulator {
  Rgb mean{0.0f}, m2{0.0f};
  int n = 0;
  void add(Rgb v) {
    ++n;
    Rgb d = v - mean;
    mean += d / float(n);
    m2 += d * (v - mean);
  }
  Rgb varianceOfMean() const { return n > 1 ? m2 / (float(n) * float(n - 1)) : Rgb(0.0f); }
};

template <class Integrator>
void renderPixels(const Scene& scene, const Integrator& integrator, const RenderOptions& opt, const Progress& progress,
                  Film& film) {
  const Camera& cam = scene.camera;
  forEachTile<PixelScratch>(film.width, film.height, "render", progress, [&](const Tile& t, PixelScratch& s) {
    s.samples.resize(size_t(opt.spp));
    for (int y = t.y0; y < t.y1; ++y)
      for (int x = t.x0; x < t.x1; ++x) {
        size_t idx = film.index(x, y);
        Rng rng(hashCombine(opt.seed, idx), 0);
        stratifiedCameraSamples(opt.spp, rng, s.samples.data(), s.strata);
        PixelAccumulator acc;
        for (const CameraSample& cs : s.samples) {
          Vec3f o, d;
          cam.generateRay({float(x) + cs.pixelOffset.x, float(y) + cs.pixelOffset.y}, cs.time01, o, d);
          Rgb L = integrator.radiance(o, d, cs.time01, rng);
          // A NaN/Inf sample is a bug upstream; never let it reach the film.
          if (!isFinite(L)) L = Rgb(0.0f);
          acc.add(L);
        }
        film.color[idx] = acc.mean;
        film.sampleCount[idx] = float(acc.n);
        film.varianceOfMean[idx] = acc.varianceOfMean();
      }
  });
}

}  // namespace

const char* const* renderMethods() { return kMethods; }

bool isRenderMethod(const std::string& name) {
  for (const char* const* m = kMethods; *m; ++m)
    if (name == *m) return true;
  return false;
}

bool methodAvailable(const std::string& name) { return name == "pathtrace"; }

Film render(const Scene& scene, const RenderOptions& opt, const Progress& progress, RenderStats& stats) {
  TDPM_ASSERT(opt.spp >= 1 && opt.maxDepth >= 1, "invalid render options");
  if (!isRenderMethod(opt.method)) throw Error("unknown method '" + opt.method + "'");
  if (!methodAvailable(opt.method))
    throw Error("method '" + opt.method + "' needs the photon-map renderer, which this build does not have yet; use pathtrace");
  Timer timer;
  Film film(scene.camera.width(), scene.camera.height());
  PathTracer pt(scene, opt.maxDepth);
  renderPixels(scene, pt, opt, progress, film);
  stats.seconds = timer.seconds();
  stats.cameraSamples = uint64_t(film.width) * uint64_t(film.height) * uint64_t(opt.spp);
  return film;
}

}  // namespace tdpm
