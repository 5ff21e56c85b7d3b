// render/renderer.cpp — methods, adaptive per-pixel sampling over the tile
// loop, and the accumulation buffer.
#include "render/renderer.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include <tbb/task_arena.h>

#include "core/error.h"
#include "core/memory.h"
#include "core/rng.h"
#include "core/timer.h"
#include "photon/tracer.h"
#include "render/camera_sample.h"
#include "render/pixel_loop.h"
#include "render/path_tracer.h"
#include "render/photon_integrator.h"
#include "render/memory_budget.h"
#include "render/photon_map.h"
#include "render/pixel_share.h"
#include "render/progressive.h"
#include "render/tile_loop.h"
#include "sampling/sampler.h"

namespace tdpm {

namespace {

// Streams a pixel's samples into a mean and the variance of that mean
// (Welford's update: stable in one pass). The sums of squares are doubles:
// radiance above ~1e19 is a valid float, its square is not (a 1e30 W light
// gave an infinite variance layer); the variance is saturated to FLT_MAX on
// output. For the adaptive rule it also keeps the mean luminance of the
// even-indexed and of the odd-indexed samples: two independent half
// estimates whose difference measures the error of the whole mean without
// being the sample variance of the values averaged (which is zero in a pixel
// that has not yet met its rare bright paths).
struct PixelAccumulator {
  Rgb mean{0.0f};
  // A pixel's sample indices are 0..n-1 (passes continue them and a pixel
  // that stops never resumes), so the halves hold (n + 1) / 2 and n / 2.
  int n = 0;  // here, not last: it fills the 4 bytes before the doubles
  double m2[3] = {0, 0, 0};
  double halfLum[2] = {0, 0};  // sums of luminance, even / odd sample indices
  void add(Rgb v, uint32_t index) {
    ++n;
    Rgb d = v - mean;
    mean += d / float(n);
    for (int c = 0; c < 3; ++c) m2[c] += double(d[c]) * double(v[c] - mean[c]);
    halfLum[index & 1] += double(v.luminance());
  }
  Rgb varianceOfMean() const {
    if (n < 2) return Rgb(0.0f);
    Rgb v;
    for (int c = 0; c < 3; ++c) v[c] = float(std::min(m2[c] / (double(n) * double(n - 1)), double(FLT_MAX)));
    return v;
  }
  // Relative error of the mean luminance from the two halves: for
  // independent halves E[(A - B)^2] = Var A + Var B = 4 Var(mean), so
  // |A - B| / 2 estimates the standard error, divided by the mean (plus a
  // floor, so near-black pixels are judged on absolute error).
  double halfError() const {
    if (n < 2) return std::numeric_limits<double>::infinity();
    double a = halfLum[0] / double((n + 1) / 2), b = halfLum[1] / double(n / 2);
    double all = (halfLum[0] + halfLum[1]) / double(n);
    return 0.5 * std::fabs(a - b) / (std::fabs(all) + kContrastFloor);
  }
  static constexpr double kContrastFloor = 0.02;
};
// What the memory pre-flight (render/memory_budget.h) charges per pixel for
// the adaptive loop: an accumulator, the activity flag and the half error.
static_assert(sizeof(PixelAccumulator) + sizeof(uint8_t) + sizeof(float) == kSamplerBytesPerPixel,
              "update kSamplerBytesPerPixel in render/renderer.h");


struct SamplingPlan {
  int batch = 16, maxSpp = 16;
  float contrast = 0.05f;
  uint64_t seed = 1;
  SamplerKind sampler = SamplerKind::Sobol;
  // The filter and the time remap of every camera sample (render/camera_sample.h):
  // a still scene, an accumulation frame's instant, an animation frame's part.
  CameraSamplePlan camera;
  // Distributed render: this rank samples only its own tiles, and the
  // half-buffer errors of every pixel are shared between passes.
  dist::Comm* comm = &dist::local();
  // Which rank renders which tiles, when distributed: empty, the first pass
  // takes them from a work queue (forEachClaimedTile) and fills this in;
  // later adaptive passes and accumulation frames keep them, so a pixel's
  // samples (and its running mean) stay on one rank. Null: the fixed
  // interleave (TileShare).
  TileOwners* owners = nullptr;
};

// The plan every render and every animation frame starts from.
SamplingPlan samplingPlanFor(const RenderOptions& opt) {
  SamplingPlan plan;
  plan.batch = opt.spp;
  plan.maxSpp = std::max(opt.spp, opt.maxSpp);
  plan.contrast = opt.contrast;
  plan.seed = opt.seed;
  plan.sampler = opt.sampler;
  plan.camera.filter = pixelFilterFor(opt);
  return plan;
}

template <class Integrator>
struct PixelScratch {
  typename Integrator::ThreadState state;
};

// One pass: every active pixel takes sample indices [first, first + count)
// of its own sequence (sampling/sampler.h), so passes extend the sequence.
template <class PixelSampler, class Integrator>
void samplePass(const Scene& scene, const Integrator& integrator, const SamplingPlan& plan, uint32_t first, int count,
                const std::vector<uint8_t>& active, std::vector<PixelAccumulator>& accs, const std::string& stage,
                const Progress& progress, int width, int height) {
  const Camera& cam = scene.camera;
  auto tileFn = [&](const Tile& t, PixelScratch<Integrator>& s) {
    samplePixels<PixelSampler>(
        t, width, cam, plan.camera, plan.seed,
        [&](size_t idx, uint32_t& f, uint32_t& c) {
          f = first;
          c = uint32_t(count);
          return active[idx] != 0;
        },
        [&](size_t idx, uint32_t i, const CameraRay& ray, typename PixelSampler::Stream& stream) {
          Rgb L = integrator.radiance(ray.origin, ray.direction, ray.time01, stream, s.state);
          // A NaN sample is a bug upstream; never let it reach the film. An
          // infinite one is a finite scene overflowing float (a tiny
          // emitter of huge power): it saturates, as a sensor would.
          if (!isFinite(L)) L = saturateSample(L);
          accs[idx].add(L, i);
        },
        [](size_t) {});
    integrator.flush(s.state);
  };
  dist::Comm& comm = *plan.comm;
  if (!comm.distributed() || !plan.owners) {
    forEachTile<PixelScratch<Integrator>>(width, height, stage, progress, tileFn, tileShareOf(comm));
  } else if (plan.owners->empty()) {
    std::vector<size_t> mine;
    {
      std::unique_ptr<dist::SharedCounter> queue = comm.sharedCounter();
      mine = forEachClaimedTile<PixelScratch<Integrator>>(width, height, stage, progress, tileFn,
                                                          [&] { return queue->fetchAdd(1); });
    }
    *plan.owners = shareTileOwners(comm, mine);
  } else {
    forEachListedTile<PixelScratch<Integrator>>(width, height, plan.owners->tiles[size_t(comm.rank())], stage,
                                                progress, tileFn);
  }
}

// Adaptive sampling in passes over the whole image: every pixel takes
// plan.batch samples; then, while the sample budget allows, a pixel takes
// another batch unless it has n >= kAdaptiveMinSamples samples and its 8
// neighbours all have a half-buffer error (PixelAccumulator::halfError) at
// or below plan.contrast * sqrt(n / kAdaptiveMinSamples). Why the sqrt: a
// pixel's squared relative error is E = s^2 / n, and one more sample lowers
// it by about E / n. Stopping when E / n <= contrast^2 / 64 gives every
// pixel the same gain per sample, which is the allocation (n proportional to
// s) that minimises the summed squared error for the samples spent; a fixed
// bound on E instead (n proportional to s^2) sent the noisy pixels to
// maxSpp and stopped the rest at 64, and on the cube caustic its expected
// MSE was 2.4x uniform sampling's for the same samples (bench/README.md,
// "Adaptive against uniform"). The pixel's own samples do not enter its decision: a rule
// that looks at them stops pixels that have not yet met their rare bright
// paths and keeps those that have until their outlier is diluted, which
// biases the image low (the old rule: 8% on the cube caustic; the same rule
// with the pixel itself in the window: -2.3% in tests/test_sampler.cpp,
// where this one is within 0.4%). Decisions use only finished passes, so
// the image does not depend on threads or tile order. The final value of a
// pixel is the mean of all its samples, and its sample indices continue
// from pass to pass. A distributed render samples its own tiles and takes
// the other ranks' errors before each decision (the neighbourhood of a
// pixel crosses tiles), so every rank decides alike, as one process would.
template <class PixelSampler, class Integrator>
void renderPixelsWith(const Scene& scene, const Integrator& integrator, const SamplingPlan& plan, const char* stage,
                      const Progress& progress, Film& film) {
  const int w = film.width, h = film.height;
  const size_t n = size_t(w) * size_t(h);
  std::vector<PixelAccumulator> accs(n);
  std::vector<uint8_t> active(n, 1);
  std::vector<float> err(n);
  uint32_t taken = 0;
  dist::testFailurePoint(*plan.comm, "render");
  for (int pass = 0;; ++pass) {
    std::string name = pass == 0 ? std::string(stage) : std::string(stage) + " (adaptive pass " + std::to_string(pass) + ")";
    samplePass<PixelSampler>(scene, integrator, plan, taken, plan.batch, active, accs, name, progress, w, h);
    taken += uint32_t(plan.batch);
    if (int(taken) + plan.batch > plan.maxSpp) break;
    for (size_t i = 0; i < n; ++i) err[i] = float(std::min(accs[i].halfError(), double(FLT_MAX)));
    if (plan.owners) sharePixels(*plan.comm, w, h, err, true, *plan.owners);
    else sharePixels(*plan.comm, w, h, err, true);
    bool any = false;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        size_t idx = size_t(y) * size_t(w) + size_t(x);
        if (!active[idx]) continue;
        if (int(taken) < kAdaptiveMinSamples) { any = true; continue; }
        float e = 0;
        for (int yy = std::max(0, y - 1); yy <= std::min(h - 1, y + 1); ++yy)
          for (int xx = std::max(0, x - 1); xx <= std::min(w - 1, x + 1); ++xx)
            if (xx != x || yy != y) e = std::max(e, err[size_t(yy) * size_t(w) + size_t(xx)]);
        if (e <= double(plan.contrast) * std::sqrt(double(taken) / double(kAdaptiveMinSamples))) active[idx] = 0;
        else any = true;
      }
    if (!any) break;
  }
  for (size_t i = 0; i < n; ++i) {
    film.color[i] = accs[i].mean;
    film.sampleCount[i] = float(accs[i].n);
    film.varianceOfMean[i] = accs[i].varianceOfMean();
  }
}

// The sampler kind is chosen here, once per render.
template <class Integrator>
void renderPixels(const Scene& scene, const Integrator& integrator, const SamplingPlan& plan, const char* stage,
                  const Progress& progress, Film& film) {
  if (plan.sampler == SamplerKind::Random)
    renderPixelsWith<RandomPixelSampler>(scene, integrator, plan, stage, progress, film);
  else
    renderPixelsWith<SobolPixelSampler>(scene, integrator, plan, stage, progress, film);
}

float defaultMaxRadius(const Scene& scene, const RenderOptions& opt) {
  if (std::isfinite(opt.estimate.maxRadius)) return opt.estimate.maxRadius;
  // Of the scene's diagonal, clipped to a multiple of the view distance
  // (Scene::extent): a huge floor must not make the search reach metres.
  float diag = scene.bounds.empty() ? 1.0f : scene.extent();
  return opt.maxRadiusFraction * diag;
}

// Every map of a fixed-budget render or accumulation frame: `wanted`
// photons of each kind, the render's communicator, the 4D tree when the
// photons are spread in time and --search 4d asks for it.
PhotonMaps tracePhotonMaps(const Scene& scene, const RenderOptions& opt, const PerMap<size_t>& wanted,
                           bool spreadInTime, float fixedTime01, uint64_t seed, const Progress& progress,
                           RenderStats& st, dist::Comm& comm) {
  PerMap<PhotonMapSettings> settings = photonMapSettingsFor(opt, wanted, seed, spreadInTime, fixedTime01);
  for (MapKind k : kAllMapKinds) {
    settings[k].trace.comm = &comm;
    settings[k].spaceTime = opt.spaceTime4D && spreadInTime;
    settings[k].kappa = opt.kappa;
  }
  PhotonMaps maps = buildPhotonMaps(scene, settings, progress);
  addMapFigures(st, maps);
  return maps;
}

constexpr size_t kMinGuidePhotons = 20000, kMaxGuidePhotons = 200000;

// The path tracer's caustic guide (render/caustic_guide.h): traced with the
// render's seed and sampler, so an image depends on nothing else.
CausticGuide buildCausticGuide(const Scene& scene, const RenderOptions& opt, const Progress& progress,
                               RenderStats& st) {
  Timer timer;
  CausticGuideSettings s;
  s.fraction = opt.causticGuiding;
  // Automatic: one guide photon per 100 camera samples, within [20k, 200k]
  // (tracing them costs ~1-3% of the eye pass: 200k take ~1 s here).
  double samples = double(scene.camera.width()) * double(scene.camera.height()) * double(opt.spp);
  s.photons = opt.guidePhotons > 0 ? opt.guidePhotons
                                   : size_t(std::clamp(samples / 100.0, double(kMinGuidePhotons), double(kMaxGuidePhotons)));
  s.seed = opt.seed;
  s.sampler = opt.sampler;
  CausticGuide guide = CausticGuide::build(scene, s, progress);
  st.guideStored = guide.photonCount();
  st.guideEmitted = guide.photonsEmitted();
  st.guideBytes = guide.enabled() ? guide.cacheBytes() + guide.photonBytes() : 0;
  st.guideCells = guide.cacheEntries();
  st.guideSeconds = timer.seconds();
  return guide;
}

PhotonIntegratorSettings integratorSettings(const Scene& scene, const RenderOptions& opt, bool timeDependent) {
  PhotonIntegratorSettings s;
  s.timeDependent = timeDependent;
  s.spaceTime4D = opt.spaceTime4D;
  s.estimate = opt.estimate;
  s.estimate.maxRadius = defaultMaxRadius(scene, opt);
  if (!std::isfinite(s.estimate.maxTimeDistance)) s.estimate.maxTimeDistance = opt.maxDtFraction * scene.shutter.length();
  // One eye sample's share of its pixel in space-time, per unit path length
  // squared: (angle of a pixel)^2 x shutter / spp, times the scale.
  Vec3f o, d0, d1;
  float cx = 0.5f * float(scene.camera.width()), cy = 0.5f * float(scene.camera.height());
  scene.camera.generateRay({cx, cy}, 0.5f, o, d0);
  scene.camera.generateRay({cx + 1.0f, cy}, 0.5f, o, d1);
  float pixelAngle = length(cross(d0, d1)) / (length(d0) * length(d1));
  s.footprintVolume = opt.kernelFootprint * pixelAngle * pixelAngle * scene.shutter.length() / float(std::max(1, opt.spp));
  s.gatherRays = opt.gatherRays;
  s.gatherGuide = opt.gatherGuide;
  s.visualizeGlobal = opt.visualizeGlobal;
  s.maxDepth = opt.maxDepth;
  return s;
}

void finishStats(const Film& film, RenderStats& st) {
  st.cameraSamples = 0;
  st.minSpp = film.sampleCount.empty() ? 0 : int(film.sampleCount[0]);
  st.maxSpp = st.minSpp;
  for (float n : film.sampleCount) {
    st.cameraSamples += uint64_t(n);
    st.minSpp = std::min(st.minSpp, int(n));
    st.maxSpp = std::max(st.maxSpp, int(n));
  }
}

}  // namespace

std::vector<std::string> sceneWarnings(const Scene& scene) {
  std::vector<std::string> w;
  if (scene.lights.empty() && scene.background.isBlack())
    w.push_back("the scene has no lights and a black background: the image will be black");
  size_t dark = 0;
  for (size_t i = 0; i < scene.lights.size(); ++i)
    if (emitsNothing(scene.lights[i])) {
      ++dark;
      w.push_back("lights[" + std::to_string(i) + "] has zero power: it adds nothing to the image");
    }
  if (dark > 0 && dark == scene.lights.size() && scene.background.isBlack())
    w.push_back("every light has zero power and the background is black: the image will be black");
  return w;
}

PixelFilter pixelFilterFor(const RenderOptions& opt) {
  return PixelFilter(opt.filter, opt.filterRadius > 0 ? opt.filterRadius : defaultFilterRadius(opt.filter));
}

namespace {
// The k-NN estimate counts of one integrator into the stats.
void addEstimateCounts(RenderStats& st, const EstimateCounts& c) {
  st.standardEstimates += c.standard;
  st.timeEstimates += c.timeDependent;
  for (MapKind k : kAllMapKinds) {
    st.maps[k].estimates += c.estimates[k];
    st.maps[k].fewEstimates += c.few[k];
  }
}

// pathtrace: the caustic guide, then the adaptive passes.
void renderPathTraced(const Scene& scene, const RenderOptions& opt, const SamplingPlan& plan, const Progress& progress,
                      RenderStats& st, Film& film) {
  // In media the guide's photons are traced through them (transmittance,
  // scattering ends a caustic path) and the volumetric path tracer
  // (render/volume_path.cpp) guides its surface vertices alike.
  CausticGuide guide = buildCausticGuide(scene, opt, progress, st);
  PathTracer pt(scene, opt.maxDepth, &guide, opt.directOnly);
  renderPixels(scene, pt, plan, "render", progress, film);
  st.guideCellsFilled = guide.cacheFilled();
}

// accumulation: N in-between frames at equally spaced times, each with its
// own maps holding 1/N of the budget, rendered at its own time and averaged.
void renderAccumulation(const Scene& scene, const RenderOptions& opt, const SamplingPlan& plan,
                        const Progress& progress, RenderStats& st, dist::Comm& comm, Film& film) {
  int frames = scene.hasMotion ? std::max(1, opt.frames) : 1;
  PerMap<size_t> perFrame = photonsWanted(opt);
  for (MapKind k : kAllMapKinds) perFrame[k] = (perFrame[k] + size_t(frames) - 1) / size_t(frames);
  SamplingPlan framePlan = plan;
  framePlan.batch = std::max(1, opt.spp / frames);
  framePlan.maxSpp = std::max(framePlan.batch, plan.maxSpp / frames);
  Film sum(film.width, film.height);
  for (int f = 0; f < frames; ++f) {
    float t01 = (float(f) + 0.5f) / float(frames);
    PhotonMaps maps =
        tracePhotonMaps(scene, opt, perFrame, false, t01, hashCombine(opt.seed, uint64_t(f)), progress, st, comm);
    PhotonIntegrator integ(scene, maps.view(), integratorSettings(scene, opt, false));
    framePlan.camera.times.fixed01 = t01;
    framePlan.seed = hashCombine(opt.seed, 0xacc0ull + uint64_t(f));
    Film one(film.width, film.height);
    std::string stage = "frame " + std::to_string(f + 1) + "/" + std::to_string(frames);
    renderPixels(scene, integ, framePlan, stage.c_str(), progress, one);
    EstimateCounts c = integ.counts();
    addEstimateCounts(st, c);
    for (size_t i = 0; i < sum.color.size(); ++i) {
      sum.color[i] += one.color[i];
      sum.sampleCount[i] += one.sampleCount[i];
      sum.varianceOfMean[i] += one.varianceOfMean[i];
    }
  }
  float inv = 1.0f / float(frames);
  // Frames near FLT_MAX can sum to infinity: saturate, as each frame did.
  for (size_t i = 0; i < film.color.size(); ++i) {
    film.color[i] = saturateSample(sum.color[i] * inv);
    film.sampleCount[i] = sum.sampleCount[i];
    film.varianceOfMean[i] = saturateSample(sum.varianceOfMean[i] * (inv * inv));  // var of an average of independent frames
  }
}

// static, standard and time: one pair of maps (static: photons at shutter
// open; standard and time: spread in time), then the adaptive passes.
void renderPhotonMapped(const Scene& scene, const RenderOptions& opt, const SamplingPlan& plan,
                        const Progress& progress, RenderStats& st, dist::Comm& comm, Film& film) {
  const RenderMethodTraits& method = renderMethodTraits(opt.method);
  bool spread = method.spreadsPhotonsInTime && scene.hasMotion;
  bool timeDependent = method.timeDependentEstimate && scene.hasMotion;
  PhotonMaps maps = tracePhotonMaps(scene, opt, photonsWanted(opt), spread, 0.0f, opt.seed, progress, st, comm);
  PhotonIntegrator integ(scene, maps.view(), integratorSettings(scene, opt, timeDependent));
  renderPixels(scene, integ, plan, "render", progress, film);
  addEstimateCounts(st, integ.counts());
}

// Distributed: rank 0 gathers the film from the tiles' owners; estimate
// counts are summed (integers) on every rank.
void gatherFilm(dist::Comm& comm, TileOwners& owners, RenderStats& st, Film& film) {
  if (!comm.distributed()) return;
  if (owners.empty()) owners = staticTileOwners(film.width, film.height, comm.size());
  sharePixels(comm, film.width, film.height, film.color, false, owners);
  sharePixels(comm, film.width, film.height, film.sampleCount, false, owners);
  sharePixels(comm, film.width, film.height, film.varianceOfMean, false, owners);
  std::vector<uint64_t> counts{st.standardEstimates, st.timeEstimates};
  for (MapKind k : kAllMapKinds) {
    counts.push_back(st.maps[k].estimates);
    counts.push_back(st.maps[k].fewEstimates);
  }
  comm.allreduceSum(counts.data(), counts.size());
  st.standardEstimates = counts[0];
  st.timeEstimates = counts[1];
  for (MapKind k : kAllMapKinds) {
    st.maps[k].estimates = counts[2 + 2 * size_t(k)];
    st.maps[k].fewEstimates = counts[3 + 2 * size_t(k)];
  }
}

}  // namespace

void checkMediaSupport(const Scene& scene, const RenderOptions& opt, bool stillImage) {
  if (!scene.hasMedia()) return;
  // Still images: every method. static and accumulation trace their volume
  // photons at fixed instants (shutter open; each frame's own) and read them
  // with the standard beam estimate, as their surface maps. Progressive
  // time / standard: fresh volume photons per pass, own k-NN beam kernels
  // shrinking per pass (render/progressive.cpp, the eye side in
  // render/photon_integrator_media.cpp). Progressive accumulation (a pass
  // at one instant) is not checked in media yet. Animations: time and
  // standard, fixed budget (each frame's beam map from the timeline's
  // segments, render/animation.cpp frameMap) and progressive (each frame a
  // progressive render of its shutter); static and accumulation have no
  // frames (renderAnimation refuses them first).
  const bool photonMethod = opt.method == RenderMethod::Time || opt.method == RenderMethod::Standard;
  const bool fixedInstants = opt.method == RenderMethod::Static || opt.method == RenderMethod::Accumulation;
  const bool renders = opt.method == RenderMethod::PathTrace || photonMethod ||
                       (stillImage && fixedInstants && !opt.progressive);
  if (!renders)
    throw Error("the scene has participating media, which need -m pathtrace, time or standard in this version" +
                std::string(stillImage ? " (static and accumulation: fixed budget only)" : " (animations: static and accumulation have no frames)") +
                "; method '" + std::string(renderMethodName(opt.method)) + "'" + (opt.progressive ? " with --progressive" : "") +
                " would render it without them");
}

// One level: the memory check, the method's render, the gather.
Film render(const Scene& scene, const RenderOptions& opt, const Progress& progress, RenderStats& st, dist::Comm& comm) {
  TDPM_ASSERT(opt.spp >= 1 && opt.maxDepth >= 1, "invalid render options");
  checkMediaSupport(scene, opt, true);
  const RenderMethodTraits& method = renderMethodTraits(opt.method);
  // Under mpirun the ranks trace shares of the volume photons as of the
  // surface photons (photon/tracer.cpp's queued batches, gathered in rank
  // order), and every rank builds the same beam map from the same store.
  if (opt.progressive) {  // render/progressive.h, from pass 0, on the same ranks
    ProgressiveState state;
    return renderProgressive(scene, opt, state, progress, st, comm);
  }
  // Before any work: an image or photon budget that cannot fit is an error,
  // not an OOM kill (render/memory_budget.h). Every rank holds the whole
  // photon maps, so every rank checks; one rank short of memory stops all.
  std::string budgetError;
  try {
    checkMemoryBudget(scene, opt, tbb::this_task_arena::max_concurrency(), availableMemoryBytes());
  } catch (const Error& e) {
    budgetError = e.what();
  }
  dist::raiseIfAnyFailed(comm, budgetError);
  Timer timer;
  st = RenderStats{};
  st.warnings = sceneWarnings(scene);
  Film film(scene.camera.width(), scene.camera.height());
  SamplingPlan plan = samplingPlanFor(opt);
  // A scene with no motion at all draws no time samples.
  plan.camera.times.moving = scene.hasMotion;
  plan.comm = &comm;
  TileOwners owners;  // filled by the first pass (a distributed render's tile queue)
  plan.owners = &owners;

  if (!method.photonMaps) renderPathTraced(scene, opt, plan, progress, st, film);
  else if (method.inBetweenFrames) renderAccumulation(scene, opt, plan, progress, st, comm, film);
  else renderPhotonMapped(scene, opt, plan, progress, st, comm, film);
  gatherFilm(comm, owners, st, film);
  finishStats(film, st);
  st.seconds = timer.seconds();
  st.peakResidentBytes = peakResidentBytes();
  return film;
}

Film renderFrame(const Scene& scene, const RenderOptions& opt, const FrameInput& frame, const Progress& progress,
                 RenderStats& st) {
  TDPM_ASSERT(opt.spp >= 1 && opt.maxDepth >= 1, "invalid render options");
  checkMediaSupport(scene, opt);
  Timer timer;
  st = RenderStats{};
  Film film(scene.camera.width(), scene.camera.height());
  SamplingPlan plan = samplingPlanFor(opt);
  setFrameTimes(plan.camera.times, scene.shutter, frame.shutter.open, frame.shutter.close);
  if (!renderMethodTraits(opt.method).photonMaps) {
    renderPathTraced(scene, opt, plan, progress, st, film);
  } else {
    PhotonIntegratorSettings s = integratorSettings(scene, opt, renderMethodTraits(opt.method).timeDependentEstimate && scene.hasMotion);
    if (!std::isfinite(opt.estimate.maxTimeDistance))
      s.estimate.maxTimeDistance = opt.maxDtFraction * frame.shutter.length();
    // One eye sample's share of space-time is of the frame's shutter, not
    // the timeline's (frames x 1/fps: 48 frames made the caustics' smallest
    // kernel ~100x too long in time, blurring them).
    if (scene.shutter.length() > 0) s.footprintVolume *= frame.shutter.length() / scene.shutter.length();
    // What moves during this frame's shutter, not the whole timeline's:
    // an eye path that meets nothing moving in the frame is the same at
    // every instant of it, as in a frame rendered alone.
    const photon::MotionBounds eyeMotion = photon::motionBoundsOver(
        scene, scene.shutter.normalized(frame.shutter.open), scene.shutter.normalized(frame.shutter.close));
    s.eyeMotion = &eyeMotion;
    PhotonIntegrator integ(scene, frame.maps, s);
    renderPixels(scene, integ, plan, "render", progress, film);
    addEstimateCounts(st, integ.counts());
  }
  finishStats(film, st);
  st.seconds = timer.seconds();
  st.peakResidentBytes = peakResidentBytes();
  return film;
}

}  // namespace tdpm
