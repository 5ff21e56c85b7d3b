// cli/render_command.cpp — the render subcommand.
#include "cli/render_command.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <sstream>

#include "cli/progress_bar.h"
#include "core/error.h"
#include "core/timer.h"
#include "image/exr.h"
#include "image/png.h"
#include "render/film_output.h"
#include "render/renderer.h"
#include "render/threads.h"
#include "scene/parse.h"
#include "scene/scene.h"

namespace tdpm::cli {

namespace {

std::string methodList() {
  std::string s;
  for (const char* const* m = renderMethods(); *m; ++m) s += std::string(s.empty() ? "" : " | ") + *m;
  return s;
}

std::string directoryOf(const std::string& path) {
  size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

std::string stemOf(const std::string& path) {
  size_t slash = path.find_last_of('/');
  std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  size_t dot = name.find_last_of('.');
  return dot == std::string::npos || dot == 0 ? name : name.substr(0, dot);
}

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

void parseResolution(const std::string& text, int& w, int& h) {
  int a = 0, b = 0;
  char x = 0, extra = 0;
  std::istringstream in(text);
  if (!(in >> a >> x >> b) || (x != 'x' && x != 'X') || (in >> extra))
    throw Error("--resolution: expected WxH (for example 640x480), got '" + text + "'");
  if (a < 1 || b < 1 || a > 65536 || b > 65536)
    throw Error("--resolution: width and height must be between 1 and 65536, got '" + text + "'");
  w = a;
  h = b;
}

// Everything that can be wrong with the flags or the output location is
// found here, before the scene is loaded or anything is rendered.
void validateOutput(const std::string& out) {
  if (!endsWith(out, ".exr")) throw Error("--output: '" + out + "' must end in .exr (the PNG preview goes beside it)");
  std::string dir = directoryOf(out);
  if (access(dir.c_str(), W_OK) != 0)
    throw Error("--output: cannot write to directory '" + dir + "' (" + std::strerror(errno) + ")");
}

std::string formatMiB(uint64_t bytes) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f MiB", double(bytes) / double(1 << 20));
  return buf;
}

// --stats: one figure per line, "name: value", on stderr after the summary
// (tests parse "peak resident memory: <bytes> bytes").
void printStats(const RenderStats& st) {
  auto u = [](uint64_t v) { return static_cast<unsigned long long>(v); };
  std::fprintf(stderr, "tdpm: stats:\n");
  std::fprintf(stderr, "  peak resident memory: %llu bytes (%s)\n", u(st.peakResidentBytes),
               formatMiB(st.peakResidentBytes).c_str());
  std::fprintf(stderr, "  bytes per photon: %.2f\n", st.bytesPerPhoton);
  std::fprintf(stderr, "  caustic photons: %llu stored, %llu emitted\n", u(st.causticStored), u(st.causticEmitted));
  std::fprintf(stderr, "  global photons: %llu stored, %llu emitted\n", u(st.globalStored), u(st.globalEmitted));
  std::fprintf(stderr, "  photon pass: %.3f s\n", st.photonSeconds);
  std::fprintf(stderr, "  render: %.3f s\n", std::max(0.0, st.seconds - st.photonSeconds));
  std::fprintf(stderr, "  estimates: %llu time-dependent, %llu standard\n", u(st.timeEstimates),
               u(st.standardEstimates));
  std::fprintf(stderr, "  samples per pixel: %d-%d\n", st.minSpp, st.maxSpp);
}

std::string formatCount(uint64_t n) {
  char buf[32];
  if (n >= 1000000) std::snprintf(buf, sizeof buf, "%.1fM", double(n) / 1e6);
  else if (n >= 1000) std::snprintf(buf, sizeof buf, "%.1fk", double(n) / 1e3);
  else std::snprintf(buf, sizeof buf, "%llu", static_cast<unsigned long long>(n));
  return buf;
}


template <class T>
T pick(const std::optional<T>& flag, const std::optional<T>& scene, T fallback) {
  return flag ? *flag : (scene ? *scene : fallback);
}

estimate::SpaceKernel spaceKernelFrom(const std::string& s) {
  if (s == "cone") return estimate::SpaceKernel::Cone;
  if (s == "epanechnikov") return estimate::SpaceKernel::Epanechnikov;
  return estimate::SpaceKernel::Uniform;
}

estimate::TimeKernel timeKernelFrom(const std::string& s) {
  return s == "epanechnikov" ? estimate::TimeKernel::Epanechnikov : estimate::TimeKernel::Uniform;
}

// Merges flags over the scene's settings over the renderer's defaults.
RenderOptions mergeOptions(const RenderArgs& a, const scene::RenderSettings& sc, const std::string& sourcePath) {
  RenderOptions o;
  o.method = pick(a.method, sc.method, o.method);
  o.spp = pick(a.spp, sc.spp, o.spp);
  o.maxSpp = pick(a.maxSpp, sc.maxSpp, o.spp);
  o.contrast = pick(a.contrast, sc.contrast, o.contrast);
  o.seed = a.seed ? uint64_t(*a.seed) : sc.seed.value_or(o.seed);
  parseSamplerKind(pick(a.sampler, sc.sampler, std::string(samplerName(o.sampler))), o.sampler);  // both checked already
  o.maxDepth = pick(a.maxDepth, sc.maxDepth, o.maxDepth);
  o.causticPhotons = size_t(pick(a.photons, sc.photons, int64_t(o.causticPhotons)));
  o.globalPhotons = size_t(pick(a.globalPhotons, sc.globalPhotons, int64_t(o.globalPhotons)));
  o.frames = pick(a.frames, sc.frames, o.frames);
  o.spaceTime4D = pick(a.search, sc.search, std::string("twopass")) == "4d";
  o.estimate.k = pick(a.k, sc.k, o.estimate.k);
  o.estimate.ks = o.estimate.k;  // the two-pass search takes k in space, keeps f*k in time
  o.estimate.fraction = pick(a.fraction, sc.fraction, o.estimate.fraction);
  o.kappa = pick(a.kappa, sc.kappa, o.kappa);
  if (a.maxRadius || sc.maxRadius) o.estimate.maxRadius = pick(a.maxRadius, sc.maxRadius, 0.0f);
  if (a.maxDt || sc.maxDt) o.estimate.maxTimeDistance = pick(a.maxDt, sc.maxDt, 0.0f);
  o.estimate.spaceKernel = spaceKernelFrom(pick(a.kernelSpace, sc.kernelSpace, std::string("uniform")));
  o.estimate.timeKernel = timeKernelFrom(pick(a.kernelTime, sc.kernelTime, std::string("uniform")));
  o.gatherRays = pick(a.gather, sc.gather, o.gatherRays);
  o.visualizeGlobal = a.globalDirect;
  // For the memory-budget error: name what set each count.
  if (!a.photons && sc.photons) o.causticPhotonsSource = "render.photons in " + sourcePath;
  if (!a.globalPhotons && sc.globalPhotons) o.globalPhotonsSource = "render.global_photons in " + sourcePath;
  if (o.maxSpp < o.spp) {
    auto source = [&](bool flag, bool scene, const char* flagName, const char* key) {
      return flag ? std::string(flagName) : scene ? "render." + std::string(key) + " in " + sourcePath : std::string("default");
    };
    throw Error("max_spp " + std::to_string(o.maxSpp) + " (" +
                source(bool(a.maxSpp), bool(sc.maxSpp), "--max-spp", "max_spp") + ") is below spp " +
                std::to_string(o.spp) + " (" + source(bool(a.spp), bool(sc.spp), "--spp", "spp") +
                "): the adaptive maximum cannot be below the first batch");
  }
  return o;
}

}  // namespace

CLI::App* addRenderCommand(CLI::App& app, RenderArgs& a) {
  CLI::App* c = app.add_subcommand("render", "Render a scene file to an OpenEXR image and a PNG preview");
  c->add_option("scene", a.scene, "Scene file (JSON, see docs/scene-format.md)")->required();
  c->add_option("-o,--output", a.output, "Output EXR path (default: <scene name>.exr here); the PNG preview goes beside it");
  c->add_option("-m,--method", a.method, "Rendering method: " + methodList() + " (default: the scene's, else time)");
  c->add_option("--spp", a.spp, "Samples per pixel in the first pass, and per extra adaptive batch (default 16)")
      ->check(CLI::Range(1, 1 << 20));
  c->add_option("--max-spp", a.maxSpp, "Adaptive sampling: at most this many samples per pixel (default: --spp, i.e. not adaptive)")
      ->check(CLI::Range(1, 1 << 20));
  c->add_option("--contrast", a.contrast,
                "Adaptive sampling: add batches while the relative standard error of a pixel's mean exceeds this (default 0.05)")
      ->check(CLI::PositiveNumber);
  c->add_option("--seed", a.seed, "Random seed >= 0: same seed, same image, whatever --threads is")
      ->check(CLI::NonNegativeNumber);
  c->add_option("--sampler", a.sampler,
                 "Sample generator: sobol (Owen-scrambled Sobol, every dimension) or random (PCG32) (default sobol)")
      ->check(CLI::IsMember({"random", "sobol"}));
  c->add_option("--max-depth", a.maxDepth, "Maximum path length in vertices (default 16)")->check(CLI::Range(1, 1024));
  c->add_option("--resolution", a.resolution, "Image size WxH (overrides the scene), e.g. 640x480");
  c->add_option("--exposure", a.exposure, "PNG preview exposure in stops (the EXR is unaffected)")
      ->check(CLI::Range(-64.0f, 64.0f));
  c->add_option("-t,--threads", a.threads, "Worker threads (default: all cores)")->check(CLI::Range(1, 1024));
  c->add_flag("-q,--quiet", a.quiet, "No progress bar and no summary");
  c->add_flag("--stats", a.stats,
              "After the summary, print peak resident memory, bytes per photon, photons stored and emitted per map, "
              "photon-pass and render seconds, estimate counts and samples per pixel (also with --quiet)");
  const std::string photonGroup = "Photon methods (static, accumulation, standard, time)";
  c->add_option("--photons", a.photons, "Caustic photons to store (default 200000)")
      ->check(CLI::Range(int64_t(0), int64_t(1) << 31))->group(photonGroup);
  c->add_option("--global-photons", a.globalPhotons, "Global photons to store (default 50000)")
      ->check(CLI::Range(int64_t(0), int64_t(1) << 31))->group(photonGroup);
  c->add_option("--frames", a.frames, "accumulation: in-between frames, each with 1/N of the photons and of the samples (default 8)")
      ->check(CLI::Range(1, 4096))->group(photonGroup);
  c->add_option("--search", a.search, "time: twopass (space, then time) or 4d (space-time kd-tree) (default twopass)")
      ->check(CLI::IsMember({"twopass", "4d"}))->group(photonGroup);
  c->add_option("--k", a.k, "Photons in the spatial search: k for standard and 4d, k_s for twopass (default 100)")
      ->check(CLI::Range(1, 4096))->group(photonGroup);
  c->add_option("--fraction", a.fraction, "twopass: fraction of the k_s kept nearest in time (default 0.5)")
      ->check(CLI::Range(1e-6f, 1.0f))->group(photonGroup);
  c->add_option("--kappa", a.kappa, "4d: weight of time in the metric d^2 = |dx|^2 + kappa dt^2 (default 1)")
      ->check(CLI::PositiveNumber)->group(photonGroup);
  c->add_option("--max-radius", a.maxRadius, "Largest search radius, scene units (default 2% of the scene's diagonal)")
      ->check(CLI::PositiveNumber)->group(photonGroup);
  c->add_option("--max-dt", a.maxDt, "twopass: largest time distance kept, seconds (default: none)")
      ->check(CLI::PositiveNumber)->group(photonGroup);
  c->add_option("--kernel-space", a.kernelSpace, "Space kernel: uniform, cone, epanechnikov (default uniform)")
      ->check(CLI::IsMember({"uniform", "cone", "epanechnikov"}))->group(photonGroup);
  c->add_option("--kernel-time", a.kernelTime, "Time kernel: uniform, epanechnikov (default uniform)")
      ->check(CLI::IsMember({"uniform", "epanechnikov"}))->group(photonGroup);
  c->add_option("--gather", a.gather, "Final-gather rays per sample for indirect light; 0: none (default 1)")
      ->check(CLI::Range(0, 1024))->group(photonGroup);
  c->add_flag("--global-direct", a.globalDirect, "Show the global photon map directly at the first diffuse hit (debugging, tests)")
      ->group(photonGroup);
  return c;
}

int runRender(const RenderArgs& a) {
  Timer total;
  const std::string output = a.output.empty() ? stemOf(a.scene) + ".exr" : a.output;
  if (a.method && !isRenderMethod(*a.method))
    throw Error("--method: unknown method '" + *a.method + "' (expected " + methodList() + ")");
  int width = 0, height = 0;
  if (a.resolution) parseResolution(*a.resolution, width, height);
  validateOutput(output);

  scene::SceneDescription desc = scene::loadScene(a.scene);
  RenderOptions opt = mergeOptions(a, desc.render, a.scene);
  float exposure = pick(a.exposure, desc.render.exposure, 0.0f);
  if (a.resolution) {
    desc.camera.width = width;
    desc.camera.height = height;
  }

  ThreadLimit limit(a.threads);
  ProgressBar bar(ProgressBar::shouldShow(a.quiet));
  auto scene = Scene::build(desc);
  RenderStats stats;
  Film film = render(*scene, opt, bar.progress(), stats);
  bar.finish();
  for (const std::string& w : stats.warnings) std::fprintf(stderr, "tdpm: warning: %s\n", w.c_str());

  image::ExrFile exr = filmToExr(film);
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%.3f", stats.seconds);
  exr.metadata = {{"tdpm/version", TDPM_VERSION},
                  {"tdpm/scene", a.scene},
                  {"tdpm/method", opt.method},
                  {"tdpm/spp", std::to_string(opt.spp)},
                  {"tdpm/max_spp", std::to_string(opt.maxSpp)},
                  {"tdpm/spp_taken", std::to_string(stats.minSpp) + "-" + std::to_string(stats.maxSpp)},
                  {"tdpm/seed", std::to_string(opt.seed)},
                  {"tdpm/sampler", samplerName(opt.sampler)},
                  {"tdpm/max_depth", std::to_string(opt.maxDepth)},
                  {"tdpm/render_seconds", seconds}};
  bool photonMethod = opt.method != "pathtrace";
  if (photonMethod) {
    exr.metadata["tdpm/caustic_photons"] = std::to_string(stats.causticStored);
    exr.metadata["tdpm/global_photons"] = std::to_string(stats.globalStored);
    if (opt.method == "time") exr.metadata["tdpm/search"] = opt.spaceTime4D ? "4d" : "twopass";
    if (opt.method == "accumulation") exr.metadata["tdpm/frames"] = std::to_string(opt.frames);
  }
  const std::string preview = image::previewPathFor(output);
  image::writeExr(output, exr);
  try {
    image::writePngPreview(preview, exr.color, exposure);
  } catch (...) {
    std::remove(output.c_str());  // both outputs or neither
    throw;
  }

  if (!a.quiet) {
    std::fprintf(stderr, "tdpm: %s, %s: %dx%d, %s camera samples (%d-%d per pixel), %.2f s in all -> %s (preview %s)\n",
                 a.scene.c_str(), opt.method.c_str(), film.width, film.height,
                 formatCount(stats.cameraSamples).c_str(), stats.minSpp, stats.maxSpp, total.seconds(), output.c_str(),
                 preview.c_str());
    if (photonMethod)
      std::fprintf(stderr,
                   "tdpm: photons: %s caustic (%s emitted), %s global (%s emitted), %.1f bytes each, %.2f s; "
                   "estimates: %llu time-dependent, %llu standard\n",
                   formatCount(stats.causticStored).c_str(), formatCount(stats.causticEmitted).c_str(),
                   formatCount(stats.globalStored).c_str(), formatCount(stats.globalEmitted).c_str(),
                   stats.bytesPerPhoton, stats.photonSeconds, static_cast<unsigned long long>(stats.timeEstimates),
                   static_cast<unsigned long long>(stats.standardEstimates));
  }
  if (a.stats) printStats(stats);
  return 0;
}

}  // namespace tdpm::cli
