// render/progressive.cpp — the pass loop of progressive photon mapping
// (render/progressive.h): one pass = fresh maps, fixed kernels, one batch of
// eye samples per pixel added into the state's float sums.
#include "render/progressive.h"

#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <exception>
#include <functional>
#include <memory>
#include <vector>

#include "core/error.h"
#include "core/memory.h"
#include "core/rng.h"
#include "core/signals.h"
#include "core/timer.h"
#include "distributed/comm.h"
#include "estimate/estimators.h"
#include "estimate/volume_estimators.h"
#include "photon/tracer.h"
#include "render/camera_sample.h"
#include "render/pixel_loop.h"
#include "render/memory_budget.h"
#include "render/photon_integrator.h"
#include "render/photon_map.h"
#include "render/progressive_check.h"
#include "render/sample_allocation.h"
#include "render/tile_loop.h"
#include "sampling/sampler.h"

namespace tdpm {

namespace {

// Pilot queries per map (pass 0): enough for a stable median, a few ms.
constexpr size_t kPilotQueries = 1024;

const char* const kLayers[] = {"sum.R", "sum.G", "sum.B", "sumsq.R", "sumsq.G", "sumsq.B", "spp"};

float maxRadiusOf(const Scene& scene, const RenderOptions& opt) {
  if (std::isfinite(opt.estimate.maxRadius)) return opt.estimate.maxRadius;
  float diag = scene.bounds.empty() ? 1.0f : scene.extent();
  return opt.maxRadiusFraction * diag;
}

// The time the passes' photons span: the scene's shutter, or an animation
// frame's (RenderOptions::frameOpen/frameClose).
double shutterOf(const Scene& scene, const RenderOptions& opt) {
  if (std::isfinite(opt.frameOpen)) return double(opt.frameClose) - double(opt.frameOpen);
  float t0, t1;
  photon::photonTimeRange(scene, t0, t1);
  return double(t1) - double(t0);
}

double median(std::vector<double>& v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// Pass 1's kernels of one map from a k-NN pilot on pass 0's photons: the
// medians, over up to kPilotQueries photons taken evenly from the store, of
// the k-NN radius (spatial kernel: k = --k photons over the whole shutter)
// and of the two-pass search's radius and window (space-time kernel: k_s in
// space, the fraction f nearest in time, at most --max-dt). Photon positions
// sample the map where its photons are, i.e. weighted by its density: the
// kernels are sized for where the map's light is (a caustic's own scale,
// not the dark floor around it).
estimate::MapKernel pilotKernel(const PhotonMap* map, const Scene& scene, const RenderOptions& opt, bool spaceTime) {
  estimate::MapKernel k;
  float maxR = maxRadiusOf(scene, opt);
  double ts = shutterOf(scene, opt);
  double maxDt = std::isfinite(opt.estimate.maxTimeDistance) ? double(opt.estimate.maxTimeDistance)
                                                              : double(opt.maxDtFraction) * ts;
  k.radius = k.spatialRadius = maxR;
  k.halfWindow = float(maxDt);
  if (!map || map->size() == 0) return k;
  estimate::Options so = opt.estimate;
  so.method = estimate::Method::Standard;
  so.maxRadius = maxR;
  estimate::Gatherer standard(map->tree, so);
  estimate::Options to = opt.estimate;
  to.method = estimate::Method::TimeTwoPass;
  to.maxRadius = maxR;
  to.maxTimeDistance = float(maxDt);
  estimate::Gatherer twoPass(map->tree, to);
  const photon::PhotonStore& s = map->store;
  size_t m = std::min(kPilotQueries, s.size()), stride = s.size() / m;
  std::vector<double> rs, rt, ht;
  estimate::ConstantBrdf brdf{Rgb(1.0f)};
  estimate::Report rep;
  for (size_t j = 0; j < m; ++j) {
    size_t i = j * stride + stride / 2;
    Vec3f p = s.position(i), n = s.direction(i);
    standard.standard(p, n, n, brdf, &rep);
    rs.push_back(double(rep.radius2));
    if (spaceTime) {
      twoPass.timeTwoPass(p, n, n, s.time(i), brdf, &rep);
      if (rep.kept > 0) {
        rt.push_back(double(rep.radius2));
        ht.push_back(0.5 * (double(rep.windowHi) - double(rep.windowLo)));
      }
    }
  }
  k.spatialRadius = float(std::sqrt(median(rs)));
  if (spaceTime && !rt.empty()) {
    k.radius = float(std::sqrt(median(rt)));
    k.halfWindow = float(std::min(median(ht), maxDt));
  } else {
    k.radius = k.spatialRadius;
  }
  // A degenerate pilot (coincident photons) must not give a zero kernel.
  float floorR = 1e-6f * scene.extent();
  k.radius = std::max(k.radius, floorR);
  k.spatialRadius = std::max(k.spatialRadius, floorR);
  k.halfWindow = std::max(k.halfWindow, float(ts / photon::kTimeBins));
  return k;
}

void storeKernel(ProgressiveMapPilot& pilot, const estimate::MapKernel& k) {
  pilot.radius = double(k.radius);
  pilot.halfWindow = double(k.halfWindow);
  pilot.spatialRadius = double(k.spatialRadius);
}

float mainAlpha(const RenderOptions& opt) {
  if (opt.alpha > 0) return opt.alpha;
  return renderMethodTraits(opt.method).defaultShrink == KernelShrink::SpaceTime ? kAlphaSpaceTime : kAlphaSpatial;
}

// ---- the volume map's pass kernels (beam estimate; scenes with media) ----
// Pass 0's volume photons are built with the render's k-NN kernels (Time or
// Standard, render/photon_map.h) as the pilot: the medians of their disc
// radii and half windows (estimate::pilotKernel) are pass 1's kernel, kept
// in state.pilot.maps[Volume] (radius, halfWindow; spatialRadius = radius).
// They are reported and kept for resume; the passes' maps use each photon's
// own k-NN kernel, shrunk (volumePassBeam).
estimate::MapKernel volumePilotKernel(const PhotonMap& map, const Scene& scene, const RenderOptions& opt,
                                      bool timeDependent) {
  estimate::MapKernel k = pilotKernel(nullptr, scene, opt, timeDependent);  // the defaults of an empty map
  if (map.beams.size() == 0) return k;
  estimate::VolumeKernel v = estimate::pilotKernel(map.beams);
  float floorR = 1e-6f * scene.extent();
  k.radius = k.spatialRadius = std::max(v.radius, floorR);
  k.halfWindow = std::max(v.halfWindow, float(shutterOf(scene, opt) / photon::kTimeBins));
  return k;
}

// The pass's beam map: the render's own k-NN kernels on the pass's fresh
// photons (each photon's r and w from its neighbours, the fixed-budget beam
// kernel of Jarosz et al.), shrunk by the schedule (docs/media-estimates.md
// "Progressive passes"): time-dependent, r and h each by kernelScale(pass,
// alpha, 3), so r^2 h follows V_{j+1}/V_1; otherwise the whole shutter and r
// by kernelScale(pass, alpha, 2). The pilot's medians (state) only report.
photon::BeamBuildOptions volumePassBeam(photon::BeamBuildOptions b, const RenderOptions& opt, int pass,
                                        bool timeDependent) {
  const double alpha = mainAlpha(opt);
  if (timeDependent) {
    b.radiusScale = b.windowScale = float(kernelScale(pass, alpha, 3));
  } else {
    b.radiusScale = float(kernelScale(pass, alpha, 2));
    b.windowScale = 1.0f;
  }
  return b;
}

// Pass 0: the volume pilot into the state. Pass 0's map is already its own
// pass kernel (the schedule's scale is 1 at pass 0).
double takeVolumePilot(ProgressiveState& state, PhotonMap& volume, const Scene& scene, const RenderOptions& opt,
                       bool timeDependent) {
  ProgressiveMapPilot& pilot = state.pilot.maps[MapKind::Volume];
  storeKernel(pilot, volumePilotKernel(volume, scene, opt, timeDependent));
  return 0.0;
}

template <class Integrator>
struct Scratch {
  typename Integrator::ThreadState state;
};

// Eye samples [pass m, (pass + 1) m) of every pixel, m = counts[pixel]
// (render/sample_allocation.h) or `spp` when `counts` is empty, so a pixel's
// samples continue one sequence across passes; the pixel's pass value goes
// to `mean` (3 floats a pixel, one pixel per tile task: no locks, any thread
// count). addPass adds it into the sums. A pixel with m = spp averages full
// samples; one with m > spp takes full samples for its first spp indices
// and the eye part alone (PhotonIntegrator::eyePart) for the others, and
// its value is mean over m of the eye part + mean over spp of the rest:
// unbiased by linearity, and the extra samples trace no photon gathers.
template <class PixelSampler>
void renderPassPixels(const Scene& scene, const PhotonIntegrator& integ, const RenderOptions& opt, int pass,
                      int spp, const std::vector<uint32_t>& counts, float fixedTime01, const std::string& stage,
                      const Progress& progress, std::vector<float>& mean) {
  const int w = scene.camera.width(), h = scene.camera.height();
  mean.assign(size_t(w) * size_t(h) * 3, 0.0f);
  float* out = mean.data();
  const Camera& cam = scene.camera;
  CameraSamplePlan plan{pixelFilterFor(opt), {}};
  plan.times.fixed01 = fixedTime01;
  plan.times.moving = scene.hasMotion;
  setFrameTimes(plan.times, scene.shutter, opt.frameOpen, opt.frameClose);
  forEachTile<Scratch<PhotonIntegrator>>(w, h, stage, progress, [&](const Tile& t, Scratch<PhotonIntegrator>& s) {
    // The pixel in flight: its count m, its first index, and its sums (all
    // samples full when m == spp; else eye and rest apart).
    uint32_t m = 0, first = 0;
    double eye[3], rest[3];
    samplePixels<PixelSampler>(
        t, w, cam, plan, opt.seed,
        [&](size_t idx, uint32_t& f, uint32_t& c) {
          m = counts.empty() ? uint32_t(spp) : counts[idx];
          first = uint32_t(pass) * m;
          f = first;
          c = m;
          for (int k = 0; k < 3; ++k) eye[k] = rest[k] = 0;
          return true;
        },
        [&](size_t, uint32_t i, const CameraRay& ray, typename PixelSampler::Stream& stream) {
          if (m == uint32_t(spp)) {
            Rgb L = integ.radiance(ray.origin, ray.direction, ray.time01, stream, s.state);
            if (!isFinite(L)) L = saturateSample(L);
            for (int c = 0; c < 3; ++c) rest[c] += double(L[c]);
            return;
          }
          Rgb e, L(0.0f);
          if (i < first + uint32_t(spp)) {
            L = saturateSample(integ.radianceSplit(ray.origin, ray.direction, ray.time01, stream, s.state, e));
            e = saturateSample(e);
            L = saturateSample(L - e);
          } else {
            e = saturateSample(integ.eyePart(ray.origin, ray.direction, ray.time01, stream, s.state));
          }
          for (int c = 0; c < 3; ++c) {
            eye[c] += double(e[c]);
            rest[c] += double(L[c]);
          }
        },
        [&](size_t idx) {
          Rgb v;
          if (m == uint32_t(spp)) {
            const double dm = double(m);
            v = saturateSample(Rgb(float(rest[0] / dm), float(rest[1] / dm), float(rest[2] / dm)));
          } else {
            Rgb r;
            for (int c = 0; c < 3; ++c) r[c] = float(eye[c] / double(m) + rest[c] / double(spp));
            v = saturateSample(r);
          }
          for (int c = 0; c < 3; ++c) out[3 * idx + size_t(c)] = v[c];
        });
    integ.flush(s.state);
  });
}

// What one pass adds to the state besides its pixel means, as doubles in a
// fixed order (they cross the network under mpirun; counts stay exact
// below 2^53).
struct PassFigures {
  PerMap<double> stored, emitted;
  double standardEstimates = 0, timeEstimates = 0, photonSeconds = 0, bytesPerPhoton = 0, seconds = 0;
  static constexpr size_t kCount = 2 * kMapKinds + 5;
  std::vector<double> pack() const {
    std::vector<double> v;
    for (MapKind k : kAllMapKinds) v.insert(v.end(), {stored[k], emitted[k]});
    v.insert(v.end(), {standardEstimates, timeEstimates, photonSeconds, bytesPerPhoton, seconds});
    return v;
  }
  static PassFigures unpack(const double* v) {
    PassFigures f;
    for (MapKind k : kAllMapKinds) {
      f.stored[k] = *v++;
      f.emitted[k] = *v++;
    }
    f.standardEstimates = v[0], f.timeEstimates = v[1], f.photonSeconds = v[2], f.bytesPerPhoton = v[3];
    f.seconds = v[4];
    return f;
  }
};

// Rank 0's pilot values (render/progressive_state.h ProgressivePilot:
// what pass 0 fixes for every later pass) into every rank's state
// (collective). `valid` false (rank 0's pass 0 was cancelled before its
// pilot ended) tells the others there are none, and they return false
// without touching their state.
bool sharePilot(dist::Comm& comm, ProgressiveState& s, bool valid = true) {
  constexpr size_t kPerMap = 4;
  double v[kPerMap * kMapKinds + 1] = {};
  auto fields = [](ProgressiveMapPilot& m) { return std::array<double*, kPerMap>{&m.pathsPerPass, &m.radius, &m.halfWindow, &m.spatialRadius}; };
  if (comm.root()) {
    for (MapKind k : kAllMapKinds)
      for (size_t i = 0; i < kPerMap; ++i) v[kPerMap * size_t(k) + i] = *fields(s.pilot.maps[k])[i];
    v[kPerMap * kMapKinds] = valid ? 1.0 : 0.0;
  }
  comm.broadcast(v, sizeof v, 0);
  if (v[kPerMap * kMapKinds] == 0.0) return false;
  for (MapKind k : kAllMapKinds)
    for (size_t i = 0; i < kPerMap; ++i) *fields(s.pilot.maps[k])[i] = v[kPerMap * size_t(k) + i];
  s.pilot.done = true;
  return true;
}

// Under mpirun a pass in flight is abandoned when the rank is asked to stop
// by SIGINT, SIGTERM or SIGHUP: Ctrl-C on mpirun sends every rank SIGTERM
// and SIGKILL one second later (Open MPI's odls_base_sigkill_timeout), too
// soon for a long round to end, so the round is dropped and rank 0 writes
// the rounds done at once. SIGUSR1, which mpirun forwards and follows with
// nothing, lets the round end (docs/distributed.md).
struct PassCancelled : std::exception {
  const char* what() const noexcept override { return "progressive pass cancelled by a signal"; }
};

bool cancelRequested() {
  int signo = signals::stopRequested();
  return signo != 0 && signo != SIGUSR1;
}

// `progress` that throws PassCancelled from the next tile or photon batch
// once cancelRequested() (the tile and photon loops report once per unit;
// TBB carries the exception to the caller and cancels the other tasks).
Progress cancellable(const Progress& progress) {
  Progress p = progress;
  p.report = [inner = progress.report](const std::string& stage, size_t done, size_t total) {
    if (cancelRequested()) throw PassCancelled();
    if (inner) inner(stage, done, total);
  };
  return p;
}

// Renders pass `pass` into `mean` (3 floats a pixel) without touching the
// sums. Reads the pilot values from `state`, or (pass 0 of a new render)
// computes them into it and then calls `afterPilot` (may be empty). Only
// warnings go to `st`; the rest is in the figures, for addPass.
PassFigures computePass(const Scene& scene, const RenderOptions& opt, ProgressiveState& state, int pass,
                        const std::vector<uint32_t>& counts, const Progress& progress, RenderStats& st,
                        std::vector<float>& mean, const std::function<void()>& afterPilot,
                        const PassMapSource& source = {}) {
  Timer timer;
  const RenderMethodTraits& method = renderMethodTraits(opt.method);
  const bool accumulation = method.inBetweenFrames;  // a pass is one frame, at its own instant
  const bool spread = method.spreadsPhotonsInTime && scene.hasMotion;
  const float passTime = accumulation && scene.hasMotion ? accumulationPassTime(pass, opt.seed) : -1.0f;

  // ---- photons: pass 0 sizes the emission with the tracer's pilot; later
  //      passes trace the same number of paths at the next path indices ----
  PerMap<PhotonMapSettings> settings =
      photonMapSettingsFor(opt, photonsWanted(opt), opt.seed, spread, passTime >= 0 ? passTime : 0.0f);
  for (MapKind kind : kAllMapKinds) {
    photon::TraceSettings& ts = settings[kind].trace;
    if (std::isfinite(opt.frameOpen)) {  // an animation frame: its shutter alone (the fixed kernel clips its window to it)
      ts.timeOpen = opt.frameOpen;
      ts.timeClose = opt.frameClose;
    }
    if (!state.pilot.done) continue;  // pass 0: the tracer's pilot sizes the emission
    // A resumed value was checked (render/progressive_check.h): a whole
    // number of batches, small enough for every pass index.
    uint64_t paths = uint64_t(state.pilot.maps[kind].pathsPerPass);
    if (paths == 0) ts.storedWanted = 0;
    settings[kind].pass.paths = paths;
    TDPM_ASSERT(paths == 0 || uint64_t(pass) + 1 <= UINT64_MAX / paths, "progressive photon path index overflows");
    settings[kind].pass.firstPath = uint64_t(pass) * paths;
  }
  const bool timeDependent = renderMethodTraits(opt.method).timeDependentEstimate && scene.hasMotion;
  // The volume map's pass kernel: its own k-NN, shrunk by the schedule.
  settings[MapKind::Volume].beam = volumePassBeam(settings[MapKind::Volume].beam, opt, pass, timeDependent);
  PhotonMaps maps = source ? source(pass, progress) : buildPhotonMaps(scene, settings, progress);
  double photonSeconds = 0;
  for (MapKind kind : kAllMapKinds) {
    const PhotonMap& m = *maps[kind];
    if (!state.pilot.done) state.pilot.maps[kind].pathsPerPass = double(m.emitted);
    photonSeconds += m.traceSeconds + m.buildSeconds;
    if (!m.warning.empty() && pass == 0) st.warnings.push_back(m.warning);
  }

  // ---- kernels: pass 1's from a k-NN pilot on pass 0's maps ----
  if (!state.pilot.done) {
    for (MapKind kind : kAllMapKinds)
      if (kind != MapKind::Volume) storeKernel(state.pilot.maps[kind], pilotKernel(maps[kind], scene, opt, timeDependent));
    photonSeconds += takeVolumePilot(state, *maps.maps[MapKind::Volume], scene, opt, timeDependent);
    state.pilot.done = true;
    if (afterPilot) afterPilot();
  }
  PassKernels k = kernelsForPass(state, opt, scene, pass);

  PhotonIntegratorSettings is;
  is.timeDependent = timeDependent;
  is.gatherRays = opt.gatherRays;
  is.visualizeGlobal = opt.visualizeGlobal;
  is.maxDepth = opt.maxDepth;
  is.fixedKernels = true;
  is.kernels = k;
  PhotonIntegrator integ(scene, maps.view(), is);
  std::string stage = "pass " + std::to_string(pass + 1) + " render";
  if (opt.sampler == SamplerKind::Random)
    renderPassPixels<RandomPixelSampler>(scene, integ, opt, pass, opt.spp, counts, passTime, stage, progress, mean);
  else
    renderPassPixels<SobolPixelSampler>(scene, integ, opt, pass, opt.spp, counts, passTime, stage, progress, mean);

  PassFigures f;
  EstimateCounts c = integ.counts();
  f.standardEstimates = double(c.standard);
  f.timeEstimates = double(c.timeDependent);
  for (MapKind kind : kAllMapKinds) {
    f.stored[kind] = double(maps[kind]->size());
    f.emitted[kind] = double(maps[kind]->emitted);
  }
  f.bytesPerPhoton = maps.bytesPerPhoton();
  f.photonSeconds = photonSeconds;
  f.seconds = timer.seconds();
  return f;
}

// Adds pass state.passesDone (its pixel means and figures) into the state:
// the one place the sums grow, for one process and for rank 0 of a job
// alike, so both make the same float operations in the same order. Each
// sum is formed in double and rounded once to the float layer; a value
// beyond the largest float (a pass mean of 1e20 squares to 1e40) cannot
// be kept: the first such pixel is returned as an error message (empty:
// none), and the caller refuses the render (issue 27 item 7: it wrote
// +Inf sums and a variance of 3.4e38, and resumed them, with exit 0).
std::string addPass(const Scene& scene, const RenderOptions& opt, ProgressiveState& state, const float* mean,
                    const std::vector<uint32_t>& counts, const PassFigures& f, RenderStats& st) {
  const int pass = state.passesDone;
  const int width = scene.camera.width();
  const size_t n = size_t(width) * size_t(scene.camera.height());
  float* sum[3] = {state.layers["sum.R"].data(), state.layers["sum.G"].data(), state.layers["sum.B"].data()};
  float* sq[3] = {state.layers["sumsq.R"].data(), state.layers["sumsq.G"].data(), state.layers["sumsq.B"].data()};
  float* count = state.layers["spp"].data();
  const float spp = float(opt.spp);
  std::string overflow;
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) {
      const double m = double(mean[3 * i + size_t(c)]);
      const double a = double(sum[c][i]) + m, b = double(sq[c][i]) + m * m;
      const bool sumFits = std::fabs(a) <= double(FLT_MAX);
      if (sumFits && b <= double(FLT_MAX)) {
        sum[c][i] = float(a);
        sq[c][i] = float(b);
      } else if (overflow.empty()) {  // the layers keep their old values: the render is refused
        const char* names[2][3] = {{"sum.R", "sum.G", "sum.B"}, {"sumsq.R", "sumsq.G", "sumsq.B"}};
        const bool inSum = !sumFits;
        char buf[400];
        std::snprintf(buf, sizeof buf,
                      "progressive pass %d: pixel (%zu, %zu) has the pass value %.3g, and its %s (%.3g) is beyond the "
                      "largest float (%.3g) the progressive state keeps: the scene is too bright for --progressive "
                      "(scale its lights down, or render with --fixed-budget)",
                      pass + 1, i % size_t(width), i / size_t(width), m, names[inSum ? 0 : 1][c], inSum ? a : b,
                      double(FLT_MAX));
        overflow = buf;
      }
    }
    count[i] += counts.empty() ? spp : float(counts[i]);
  }
  st.standardEstimates += uint64_t(f.standardEstimates);
  st.timeEstimates += uint64_t(f.timeEstimates);
  double emitted = 0, stored = 0;  // over the maps, in kind order
  for (MapKind k : kAllMapKinds) {
    st.maps[k].stored += size_t(f.stored[k]);
    st.maps[k].emitted += uint64_t(f.emitted[k]);
    emitted += f.emitted[k];
    stored += f.stored[k];
  }
  st.photonSeconds += f.photonSeconds;
  if (stored > 0) st.bytesPerPhoton = f.bytesPerPhoton;

  const bool timeDependent = renderMethodTraits(opt.method).timeDependentEstimate && scene.hasMotion;
  PassKernels k = kernelsForPass(state, opt, scene, pass);
  state.passesDone = pass + 1;
  ProgressiveTotals& t = state.totals;
  t.photonsEmitted += emitted;
  t.photonsStored += stored;
  // Reported (not read back): the caustic map's kernel, the one users tune.
  const estimate::MapKernel& kc = k[MapKind::Caustic];
  t.kernelRadius = double(timeDependent ? kc.radius : kc.spatialRadius);
  t.kernelSpatialRadius = double(kc.spatialRadius);
  t.kernelHalfWindow = timeDependent ? double(kc.halfWindow) : 0.0;
  t.seconds += f.seconds;
  return overflow;
}

}  // namespace

double kernelScale(int pass, double alpha, int dims) {
  double v = 1.0;
  for (int j = 1; j <= pass; ++j) v *= (double(j) + alpha) / double(j + 1);
  return std::pow(v, 1.0 / double(dims));
}

float accumulationPassTime(int pass, uint64_t seed) {
  uint32_t bits = uint32_t(pass);
  bits = (bits << 16) | (bits >> 16);
  bits = ((bits & 0x00ff00ffu) << 8) | ((bits & 0xff00ff00u) >> 8);
  bits = ((bits & 0x0f0f0f0fu) << 4) | ((bits & 0xf0f0f0f0u) >> 4);
  bits = ((bits & 0x33333333u) << 2) | ((bits & 0xccccccccu) >> 2);
  bits = ((bits & 0x55555555u) << 1) | ((bits & 0xaaaaaaaau) >> 1);
  // Rotation (Cranley-Patterson) by a hash of the seed, mod 1 in 32-bit fixed point.
  bits += uint32_t(mix64(seed ^ 0xacc0ull) >> 32);
  return std::min(float(bits >> 8) * 0x1p-24f, 0x1.fffffep-1f);
}

PassKernels kernelsForPass(const ProgressiveState& state, const RenderOptions& opt, const Scene& scene, int pass) {
  const bool time = renderMethodTraits(opt.method).timeDependentEstimate;  // has a space-time kernel
  const double alpha = mainAlpha(opt);
  const double binWidth = shutterOf(scene, opt) / photon::kTimeBins;
  // time: the space-time kernel (d = 3) takes the main alpha, its spatial
  // fallback 2/3; the other variants have only the spatial kernel (d = 2).
  const double s3 = kernelScale(pass, alpha, 3);
  const double s2 = kernelScale(pass, time ? kAlphaSpatial : alpha, 2);
  auto one = [&](MapKind kind) {
    const ProgressiveMapPilot& pilot = state.pilot.maps[kind];
    estimate::MapKernel k;
    double r1 = pilot.radius, h1 = pilot.halfWindow;
    double r = r1 * s3, h = h1 * s3;
    if (h < binWidth && h1 > 0) {
      // Below one time bin the window cannot resolve more (photon/store.h):
      // floor it and keep the volume schedule r^2 h in the radius.
      r *= std::sqrt(h / binWidth);
      h = binWidth;
    }
    k.radius = float(r);
    k.halfWindow = float(h);
    k.spatialRadius = float(pilot.spatialRadius * s2);
    return k;
  };
  PassKernels all;
  for (MapKind kind : kAllMapKinds) all[kind] = one(kind);
  return all;
}

void runProgressivePass(const Scene& scene, const RenderOptions& opt, ProgressiveState& state,
                        const Progress& progress, RenderStats& st, const std::vector<uint32_t>& counts,
                        const PassMapSource& source) {
  std::vector<float> mean;
  PassFigures f = computePass(scene, opt, state, state.passesDone, counts, progress, st, mean, {}, source);
  std::string overflow = addPass(scene, opt, state, mean.data(), counts, f, st);
  if (!overflow.empty()) throw Error(overflow);
}

Film filmFromState(const ProgressiveState& state, int width, int height) {
  Film film(width, height);
  const size_t n = size_t(width) * size_t(height);
  const double p = double(std::max(1, state.passesDone));
  auto layer = [&](const char* name) -> const std::vector<float>& { return state.layers.at(name); };
  const std::vector<float>* sum[3] = {&layer("sum.R"), &layer("sum.G"), &layer("sum.B")};
  const std::vector<float>* sq[3] = {&layer("sumsq.R"), &layer("sumsq.G"), &layer("sumsq.B")};
  const std::vector<float>& spp = layer("spp");
  for (size_t i = 0; i < n; ++i) {
    Rgb mean, var(0.0f);
    for (int c = 0; c < 3; ++c) {
      double m = double((*sum[c])[i]) / p;
      mean[c] = float(m);
      // Variance of the mean of the pass means (passes are independent).
      if (state.passesDone >= 2) {
        double v = (double((*sq[c])[i]) / p - m * m) * p / (p - 1.0) / p;
        var[c] = float(std::min(std::max(v, 0.0), double(FLT_MAX)));
      }
    }
    film.color[i] = saturateSample(mean);
    film.varianceOfMean[i] = saturateSample(var);
    film.sampleCount[i] = spp[i];
  }
  return film;
}

namespace {

// Where the pass loop stands, for the progress bar and pass lines.
WorkPosition passPosition(const ProgressiveState& state, const RenderOptions& opt, double limit) {
  return WorkPosition{"pass", size_t(state.passesDone), size_t(std::max(0, opt.passes)), limit,
                      uint64_t(state.totals.photonsEmitted)};
}

// A new state gets its zero layers and its settings; a resumed one is
// checked against the image size. The sums live on rank 0 only.
void prepareState(ProgressiveState& state, const RenderOptions& opt, int w, int h, dist::Comm& comm) {
  const size_t n = size_t(w) * size_t(h);
  if (state.empty()) {
    state.layers.clear();
    state.pilot = {};
    state.totals = {};
  }
  for (const char* name : kLayers) {
    if (!comm.root()) break;  // the sums live on rank 0 only
    std::vector<float>& l = state.layers[name];
    if (state.empty()) l.assign(n, 0.0f);
    else if (l.size() != n)
      throw Error(std::string("progressive state: layer '") + name + "' holds " + std::to_string(l.size()) +
                  " pixels, the image has " + std::to_string(n) + " (" + std::to_string(w) + "x" + std::to_string(h) + ")");
  }
  if (state.settings.empty()) {
    char a[32];
    std::snprintf(a, sizeof a, "%.9g", double(mainAlpha(opt)));
    state.settings = {{"method", renderMethodName(opt.method)},
                      {"seed", std::to_string(opt.seed)},
                      {"sampler", samplerName(opt.sampler)},
                      {"spp", std::to_string(opt.spp)},
                      {"alpha", a},
                      {"max_depth", std::to_string(opt.maxDepth)},
                      {"gather", std::to_string(opt.gatherRays)},
                      {"k", std::to_string(opt.estimate.k)},
                      {"resolution", std::to_string(w) + "x" + std::to_string(h)}};
    for (MapKind k : kAllMapKinds)
      if (mapKindInUse(opt, k)) state.settings[mapKindInfo(k).optionName] = std::to_string(opt.*mapKindInfo(k).photons);
  }
}

// One process: passes until --passes are done, the time limit is reached
// or a signal asks to stop (after the pass in flight).
void runLocalPasses(const Scene& scene, const RenderOptions& opt, ProgressiveState& state, const Progress& progress,
                    RenderStats& st, const std::vector<uint32_t>& counts, double limit, const Timer& timer) {
  for (;;) {
    if (opt.passes > 0 && state.passesDone >= opt.passes) break;
    if (state.passesDone >= maxProgressivePasses()) break;  // what a resume accepts (progressive_check.h)
    runProgressivePass(scene, opt, state, progress, st, counts);
    progress.at(passPosition(state, opt, limit));
    if (limit > 0 && timer.seconds() >= limit) break;
    if (signals::stopRequested()) break;
  }
}

// Rounds of N passes (docs/distributed.md): rank r runs pass first + r
// alone, rank 0 adds the round's passes in pass order with addPass (the
// same float additions as one process), then the job decides together
// whether to stop. Pass 0 of a new render computes the pilot values on
// rank 0, which sends them before rendering its pixels; the others wait
// for them, then run their passes. Returns true when a round was dropped
// (a signal: the rounds done before it stand).
bool runDistributedRounds(const Scene& scene, const RenderOptions& opt, ProgressiveState& state,
                          const Progress& progress, RenderStats& st, const std::vector<uint32_t>& counts, double limit,
                          const Timer& timer, dist::Comm& comm) {
  const int N = comm.size(), rank = comm.rank();
  for (bool stop = false; !stop;) {
    const int first = state.passesDone;
    const int inRound =
        std::min(opt.passes > 0 ? std::min(N, opt.passes - first) : N, maxProgressivePasses() - first);
    if (inRound <= 0) break;
    const bool has = rank < inRound;
    const bool needPilot = !state.pilot.done;
    bool cancelled = false, pilotSent = false;
    if (needPilot && !comm.root()) cancelled = !sharePilot(comm, state);
    std::vector<float> mean;
    std::vector<double> figures;
    if (has && !cancelled) {
      RenderStats own;  // warnings (rank 0's pass 0 only)
      try {
        PassFigures f = computePass(scene, opt, state, first + rank, counts, cancellable(comm.root() ? progress : Progress{}),
                                    own, mean, [&] {
                                      if (needPilot) sharePilot(comm, state);
                                      pilotSent = true;
                                    });
        if (comm.root()) st.warnings.insert(st.warnings.end(), own.warnings.begin(), own.warnings.end());
        figures = f.pack();
      } catch (const PassCancelled&) {
        cancelled = true;
      }
    }
    if (needPilot && comm.root() && !pilotSent) sharePilot(comm, state, false);  // the others wait for it
    // A rank that abandoned its pass drops the whole round: the job
    // stops with the rounds done before it (an integer sum, so every
    // rank decides alike).
    uint64_t dropped = cancelled ? 1 : 0;
    comm.allreduceSum(&dropped, 1);
    if (dropped > 0) return true;
    std::vector<PassFigures> roundFigures;
    dist::combineRoundOnRoot(comm, figures, has,
                             [&](const double* v, size_t) { roundFigures.push_back(PassFigures::unpack(v)); });
    size_t next = 0;
    std::string overflow;
    dist::combineRoundOnRoot(comm, mean, has, [&](const float* v, size_t) {
      std::string e = addPass(scene, opt, state, v, counts, roundFigures[next++], st);
      if (overflow.empty()) overflow = e;
    });
    dist::raiseIfAnyFailed(comm, overflow);  // rank 0 alone adds: every rank learns it
    state.passesDone = first + inRound;
    if (comm.root()) progress.at(passPosition(state, opt, limit));
    // Stop when rank 0 says so (time limit) or any rank was asked to stop
    // by a signal (mpirun forwards SIGTERM to every rank).
    uint64_t want = uint64_t((comm.root() && limit > 0 && timer.seconds() >= limit) || signals::stopRequested());
    comm.allreduceSum(&want, 1);
    stop = want > 0;
  }
  return false;
}

}  // namespace

ProgressiveStart startProgressive(const Scene& scene, const RenderOptions& opt, ProgressiveState& state,
                                  const Progress& progress, RenderStats& st, dist::Comm& comm) {
  if (!renderMethodTraits(opt.method).progressive)
    throw Error("--progressive works with the methods time, accumulation and standard, not '" +
                std::string(renderMethodName(opt.method)) + "'");
  TDPM_ASSERT(opt.spp >= 1 && opt.maxDepth >= 1, "invalid render options");
  checkMediaSupport(scene, opt, true);  // the CLI and resume come here, not through render()
  // One pass's memory, as a fixed-budget render of the same photon counts
  // (a fixed-budget accumulation would split them over its frames: a pass
  // holds them all, as standard does).
  RenderOptions budget = opt;
  if (renderMethodTraits(budget.method).inBetweenFrames) budget.method = RenderMethod::Standard;
  std::string budgetError;
  try {
    checkMemoryBudget(scene, budget, tbb::this_task_arena::max_concurrency(), availableMemoryBytes());
  } catch (const Error& e) {
    if (!comm.distributed()) throw;
    budgetError = e.what();
  }
  dist::raiseIfAnyFailed(comm, budgetError);
  // Under mpirun rank 0 holds the state (read by --resume, written at the
  // end); the others need where it stands and pass 0's pilot values.
  if (comm.distributed()) {
    state.passesDone = comm.broadcastInt(state.passesDone);
    if (!state.empty()) sharePilot(comm, state);
  }
  st = RenderStats{};
  st.warnings = sceneWarnings(scene);
  prepareState(state, opt, scene.camera.width(), scene.camera.height(), comm);
  ProgressiveStart start;
  start.limit = opt.timeLimitSeconds;
  if (opt.passes <= 0 && !(start.limit > 0)) start.limit = kDefaultProgressiveSeconds;
  progress.at(passPosition(state, opt, start.limit));
  // Samples per pixel and pass: the same map in every run and on every rank
  // (a function of scene, options and seed; render/sample_allocation.h).
  start.counts = passSampleCounts(scene, opt, progress, comm);
  return start;
}

Film finishProgressive(const Scene& scene, const ProgressiveState& state, RenderStats& st, double seconds) {
  const int w = scene.camera.width(), h = scene.camera.height();
  Film film = filmFromState(state, w, h);
  st.cameraSamples = 0;
  st.minSpp = film.sampleCount.empty() ? 0 : int(film.sampleCount[0]);
  st.maxSpp = st.minSpp;
  for (float c : film.sampleCount) {
    st.cameraSamples += uint64_t(c);
    st.minSpp = std::min(st.minSpp, int(c));
    st.maxSpp = std::max(st.maxSpp, int(c));
  }
  st.seconds = seconds;
  st.peakResidentBytes = peakResidentBytes();
  return film;
}

// One level: the checks and the state (startProgressive), the pass loop
// (local or in rounds over the ranks), the film from the sums.
Film renderProgressive(const Scene& scene, const RenderOptions& opt, ProgressiveState& state,
                       const Progress& progress, RenderStats& st, dist::Comm& comm) {
  Timer timer;
  const ProgressiveStart start = startProgressive(scene, opt, state, progress, st, comm);
  if (!comm.distributed()) {
    runLocalPasses(scene, opt, state, progress, st, start.counts, start.limit, timer);
  } else {
    const bool roundDropped =
        runDistributedRounds(scene, opt, state, progress, st, start.counts, start.limit, timer, comm);
    if (roundDropped && state.passesDone == 0)  // every rank knows: an agreed error, rank 0 says it
      throw dist::AgreedError("stopped by a signal before the first round of passes ended: nothing to write");
    if (!comm.root()) {
      st.seconds = timer.seconds();
      return Film();
    }
  }
  return finishProgressive(scene, state, st, timer.seconds());
}

}  // namespace tdpm
