// cli/render_command.cpp — the render subcommand.
#include "cli/render_command.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <memory>
#include <sstream>
#include <vector>

#include "cli/animation_command.h"
#include "cli/flag_ranges.h"
#include "cli/frame_pattern.h"
#include "cli/path_names.h"
#include "cli/progress_bar.h"
#include "cli/resume.h"
#include "render/progressive_io.h"
#include "cli/progressive_options.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/signals.h"
#include "core/memory.h"
#include "core/timer.h"
#include "dist/comm.h"
#include "image/exr.h"
#include "image/png.h"
#include "import/pbrt_import.h"
#include "photon/store.h"
#include "render/film_output.h"
#include "render/progressive.h"
#include "render/renderer.h"
#include "render/threads.h"
#include "scene/limits.h"
#include "scene/parse.h"
#include "scene/scene.h"

namespace tdpm::cli {

namespace {

namespace limits = scene::limits;
static_assert(limits::kTimeBins == photon::kTimeBins, "the kappa range in scene/limits.h assumes the photon time bins");

std::string methodList() {
  std::string s;
  for (const char* const* m = renderMethods(); *m; ++m) s += std::string(s.empty() ? "" : " | ") + *m;
  return s;
}

// pbrt's Film "filename" (often .exr, .png or .pfm): tdpm writes EXR, so
// the name keeps its directory and stem and gets the .exr extension.
std::string exrNameForFilm(const std::string& filmName) {
  if (endsWith(filmName, ".exr")) return filmName;
  size_t slash = filmName.find_last_of('/');
  size_t dot = filmName.find_last_of('.');
  std::string stem = dot == std::string::npos || (slash != std::string::npos && dot < slash) ? filmName : filmName.substr(0, dot);
  return stem + ".exr";
}

void parseResolution(const std::string& text, int& w, int& h) {
  int a = 0, b = 0;
  char x = 0, extra = 0;
  std::istringstream in(text);
  if (!(in >> a >> x >> b) || (x != 'x' && x != 'X') || (in >> extra))
    throw Error("--resolution: expected WxH (for example 640x480), got '" + text + "'");
  if (a < 1 || b < 1 || a > limits::kMaxResolution || b > limits::kMaxResolution)
    throw Error("--resolution: width and height must be between 1 and " + std::to_string(limits::kMaxResolution) +
                ", got '" + text + "'");
  w = a;
  h = b;
}

void refuseOverwritingInput(const std::string& out, const std::string& preview, const std::string& input,
                            const std::string& what);

// Everything that can be wrong with the output location is found here,
// before the scene is loaded or anything is rendered: the name, the
// directory, a directory or other non-file in the way, a name too long for
// the file system (also the temporary's), a dangling symbolic link, for the
// EXR and its PNG preview alike (core/atomic_file checkOutputPath).
void validateOutput(const std::string& out, const std::string& preview, const std::string& scenePath) {
  if (!endsWith(out, ".exr")) throw Error("--output: '" + out + "' must end in .exr (the PNG preview goes beside it)");
  std::string dir = directoryOf(out);
  if (access(dir.c_str(), W_OK) != 0)
    throw Error("--output: cannot write to directory '" + dir + "' (" + std::strerror(errno) + ")");
  try {
    checkOutputPath(out);
    checkOutputPath(preview);
  } catch (const Error& e) {
    throw Error(std::string("--output: ") + e.what());
  }
  if (sameFile(out, preview))
    throw Error("--output: '" + out + "' and its PNG preview '" + preview + "' are the same file");
  refuseOverwritingInput(out, preview, scenePath, "the scene file");
}

// An output that is an input (the same file, also through a link) would
// destroy it: refused, as compare refuses it for --csv.
void refuseOverwritingInput(const std::string& out, const std::string& preview, const std::string& input,
                            const std::string& what) {
  for (const std::string* o : {&out, &preview})
    if (sameFile(*o, input))
      throw Error("--output: '" + *o + "' is " + what + " '" + input + "'; writing it would destroy an input");
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
  if (st.guideStored > 0)
    std::fprintf(stderr, "  caustic guide: %llu stored, %llu emitted, %s reserved, %.3f s; cache %llu of %llu sub-cells filled\n",
                 u(st.guideStored), u(st.guideEmitted), formatMiB(st.guideBytes).c_str(), st.guideSeconds,
                 u(st.guideCellsFilled), u(st.guideCells));
  std::fprintf(stderr, "  photon pass: %.3f s\n", st.photonSeconds);
  std::fprintf(stderr, "  render: %.3f s\n", std::max(0.0, st.seconds - st.photonSeconds));
  std::fprintf(stderr, "  estimates: %llu time-dependent, %llu standard\n", u(st.timeEstimates),
               u(st.standardEstimates));
  // Issue 24: where an estimate reads few photons it is noisy (and was biased).
  if (st.causticEstimates + st.globalEstimates > 0)
    std::fprintf(stderr, "  estimates from fewer than %d photons: caustic %llu of %llu, global %llu of %llu\n",
                 estimate::kFewPhotons, u(st.fewCausticEstimates), u(st.causticEstimates), u(st.fewGlobalEstimates),
                 u(st.globalEstimates));
  std::fprintf(stderr, "  samples per pixel: %d-%d\n", st.minSpp, st.maxSpp);
}

// One rank's share of a distributed render, for --stats.
struct RankSeconds {
  uint64_t bytesSent = 0;
  double commSeconds = 0;     // in collectives, waiting for slower ranks included
  double commCpuSeconds = 0;  // CPU of those (MPI busy-polls while waiting)
  double renderSeconds = 0;
  double cpuSeconds = 0;      // the process's user + system CPU so far
};

double processCpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  auto s = [](const timeval& t) { return double(t.tv_sec) + 1e-6 * double(t.tv_usec); };
  return s(u.ru_utime) + s(u.ru_stime);
}

// Every rank's figures on rank 0 (one entry per rank; one process: itself).
std::vector<RankSeconds> gatherRankStats(dist::Comm& comm, double renderSeconds) {
  RankSeconds mine{comm.stats().bytesSent, comm.stats().seconds, comm.stats().cpuSeconds, renderSeconds,
                   processCpuSeconds()};
  std::vector<RankSeconds> all(size_t(comm.size()));
  comm.gathervToRoot(&mine, all.data(), std::vector<uint64_t>(size_t(comm.size()), sizeof(RankSeconds)));
  return all;
}

// --stats of a distributed render: one line per rank.
void printRankStats(const std::vector<RankSeconds>& ranks) {
  if (ranks.size() < 2) return;
  std::fprintf(stderr, "  ranks: %zu (bytes sent counted once per receiving rank; communication time includes "
                       "waiting for slower ranks)\n", ranks.size());
  for (size_t r = 0; r < ranks.size(); ++r) {
    const RankSeconds& k = ranks[r];
    double share = k.renderSeconds > 0 ? 100.0 * k.commSeconds / k.renderSeconds : 0.0;
    std::fprintf(stderr,
                 "  rank %zu: %llu bytes sent (%s), %.3f s in communication of %.3f s rendering (%.1f%%); "
                 "CPU %.3f s in all, %.3f s of it in communication\n",
                 r, static_cast<unsigned long long>(k.bytesSent), formatMiB(k.bytesSent).c_str(), k.commSeconds,
                 k.renderSeconds, share, k.cpuSeconds, k.commCpuSeconds);
  }
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
  parseFilterKind(pick(a.filter, sc.filter, std::string(filterName(o.filter))), o.filter);
  o.filterRadius = pick(a.filterRadius, sc.filterRadius, o.filterRadius);
  o.maxDepth = pick(a.maxDepth, sc.maxDepth, o.maxDepth);
  o.causticGuiding = a.causticGuiding.value_or(o.causticGuiding);
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
  if (a.kernelFootprint) o.kernelFootprint = *a.kernelFootprint;
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

// accumulation renders each of its N frames with spp/N samples per pixel
// (at least 1) and its own photon maps of 1/N of the counts: with more
// frames than samples, or counts that are not multiples of N, the totals
// differ from what was asked. Said before the render.
std::vector<std::string> accumulationSppWarnings(const RenderOptions& o, bool hasMotion) {
  std::vector<std::string> w;
  if (o.method != "accumulation" || !hasMotion || o.frames <= 1) return w;
  int batch = std::max(1, o.spp / o.frames);
  int maxBatch = std::max(batch, std::max(o.spp, o.maxSpp) / o.frames);
  if (batch * o.frames != o.spp || (o.maxSpp > o.spp && maxBatch * o.frames != o.maxSpp))
    w.push_back("accumulation: " + std::to_string(o.frames) + " frames of " + std::to_string(batch) +
                (maxBatch > batch ? "-" + std::to_string(maxBatch) : std::string()) +
                " samples per pixel each take " + std::to_string(batch * o.frames) +
                (maxBatch > batch ? "-" + std::to_string(maxBatch * o.frames) : std::string()) +
                " samples per pixel in all, not the " + std::to_string(o.spp) +
                " asked for (make --spp a multiple of --frames)");
  return w;
}

// After the render: every frame's photon pass emits at least one batch of
// paths, so many frames with few photons each store more than asked.
void warnAccumulationPhotons(const RenderOptions& o, bool hasMotion, const RenderStats& st) {
  if (o.method != "accumulation") return;
  const int frames = hasMotion ? std::max(1, o.frames) : 1;
  auto check = [&](const char* kind, size_t asked, size_t stored) {
    if (asked > 0 && double(stored) > 1.1 * double(asked))
      std::fprintf(stderr,
                   "tdpm: warning: accumulation: %s %s photons stored, not the %s asked for: each of the %d frames "
                   "traces at least one batch of photon paths (fewer --frames or more photons avoid it)\n",
                   formatCount(stored).c_str(), kind, formatCount(asked).c_str(), frames);
  };
  check("caustic", o.causticPhotons, st.causticStored);
  check("global", o.globalPhotons, st.globalStored);
}

}  // namespace

RenderOptions renderOptionsFor(const RenderArgs& a, const scene::SceneDescription& desc) {
  return mergeOptions(a, desc.render, a.scene);
}

CLI::App* addRenderCommand(CLI::App& app, RenderArgs& a) {
  CLI::App* c = app.add_subcommand("render", "Render a scene file to an OpenEXR image and a PNG preview");
  c->add_option("scene", a.scene, "Scene file: JSON (docs/scene-format.md) or pbrt-v3/v4 by the .pbrt extension (docs/pbrt-import.md)")->required();
  c->add_option("-o,--output", a.output, "Output EXR path (default: <scene name>.exr here, or a pbrt Film's filename as .exr); the PNG preview goes beside it. Both are written to "
                "temporaries and renamed into place together: on any failure or signal the old pair stays. A "
                "symbolic link is written through (its target is replaced, keeping its mode); a path that is an input "
                "(scene, mesh) is refused. Checked before rendering");
  c->add_option("-m,--method", a.method, "Rendering method: " + methodList() + " (default: the scene's, else time)");
  c->add_option("--spp", a.spp, "Samples per pixel in the first pass, and per extra adaptive batch (default 16)")
      ->check(rangeOf(limits::kSpp));
  c->add_option("--max-spp", a.maxSpp, "Adaptive sampling: at most this many samples per pixel (default: --spp, i.e. not adaptive)")
      ->check(rangeOf(limits::kSpp));
  c->add_option("--contrast", a.contrast,
                "Adaptive sampling: add batches while the relative standard error of a pixel's mean (judged on its 8 neighbours) exceeds this x sqrt(n / 64) after n samples, so that every pixel stops at the same error gain per sample (default 0.05; docs/sampling.md)")
      ->check(CLI::PositiveNumber);
  c->add_option("--seed", a.seed, "Random seed >= 0: same seed, same image, whatever --threads is")
      ->check(CLI::NonNegativeNumber);
  c->add_option("--sampler", a.sampler,
                 "Sample generator: sobol (Owen-scrambled Sobol, every dimension) or random (PCG32) (default sobol)")
      ->check(CLI::IsMember({"random", "sobol"}));
  c->add_option("--filter", a.filter,
                "Pixel filter, applied by drawing each sample's position from it: box (the pixel, default) or gaussian "
                "(pbrt-v4's: sigma 0.5 px, radius 1.5 px; blurs about one pixel; docs/sampling.md)")
      ->check(CLI::IsMember({"box", "gaussian"}));
  c->add_option("--filter-radius", a.filterRadius, "Pixel filter radius in pixels (default: box 0.5, gaussian 1.5)")
      ->check(rangeOf(limits::kFilterRadius));
  c->add_option("--max-depth", a.maxDepth, "Maximum path length in vertices (default 16)")->check(rangeOf(limits::kMaxDepth));
  c->add_option("--caustic-guiding", a.causticGuiding,
                "pathtrace: share of the first two diffuse vertices' continuation samples aimed where nearby caustic "
                "photons left the last mirror or glass (a small photon map traced first; less where those photons "
                "are far; an unbiased mixture with the BSDF; 0 turns it off; default 0.5; docs/sampling.md)")
      ->check(rangeOf(limits::kCausticGuiding));
  c->add_option("--resolution", a.resolution, "Image size WxH (overrides the scene), e.g. 640x480");
  c->add_option("--exposure", a.exposure, "PNG preview exposure in stops (the EXR is unaffected)")
      ->check(rangeOf(limits::kExposure));
  c->add_option("--resume", a.resume,
                 "Continue the progressive render that wrote this EXR (needs --progressive): its passes, kept in the "
                 "file, are the start, and the new passes are averaged in. The scene and every setting that changes "
                 "the image must be the same (an error names what differs); --threads, --passes, --time-limit and "
                 "--exposure may change. --output may name the same file: it is replaced atomically (docs/resume.md)");
  c->add_option("-t,--threads", a.threads, "Worker threads (default: all cores)")->check(CLI::Range(1, 1024));
  c->add_flag("-q,--quiet", a.quiet, "No progress bar and no summary");
  c->add_flag("--stats", a.stats,
              "After the summary, print peak resident memory, bytes per photon, photons stored and emitted per map, "
              "photon-pass and render seconds, estimate counts and samples per pixel (also with --quiet); under mpirun "
              "also bytes sent and seconds spent in communication per rank");
  const std::string photonGroup = "Photon methods (static, accumulation, standard, time)";
  c->add_option("--photons", a.photons, "Caustic photons to store (default 200000)")
      ->check(rangeOf(limits::kPhotons))->group(photonGroup);
  c->add_option("--global-photons", a.globalPhotons, "Global photons to store (default 50000)")
      ->check(rangeOf(limits::kPhotons))->group(photonGroup);
  c->add_option("--frames", a.frames, "accumulation: in-between frames, each with 1/N of the photons and of the samples (default 8); every "
                "frame takes at least 1 sample per pixel and one batch of photon paths, so frames above --spp or "
                "far above the photon counts raise the totals (a warning says so)")
      ->check(rangeOf(limits::kFrames))->group(photonGroup);
  c->add_option("--search", a.search, "time: twopass (space, then time) or 4d (space-time kd-tree) (default twopass)")
      ->check(CLI::IsMember({"twopass", "4d"}))->group(photonGroup);
  c->add_option("--k", a.k, "Photons in the spatial search: k for standard and 4d, k_s for twopass (default 100)")
      ->check(rangeOf(limits::kK))->group(photonGroup);
  c->add_option("--fraction", a.fraction, "twopass: fraction of the k_s kept nearest in time (default 0.5)")
      ->check(rangeOf(limits::kFraction))->group(photonGroup);
  c->add_option("--kappa", a.kappa, "4d: weight of time in the metric d^2 = |dx|^2 + kappa dt^2 (default 1; for a 1 s shutter at least 7.7e-34 and at most 8.5e37, see docs/scene-format.md)")
      ->check(CLI::PositiveNumber)->group(photonGroup);
  c->add_option("--max-radius", a.maxRadius, "Largest search radius, scene units (default 2% of the scene's diagonal, the diagonal clipped to 20x the camera's distance to its target)")
      ->check(rangeOf(limits::kMaxRadius))->group(photonGroup);
  c->add_option("--max-dt", a.maxDt, "twopass: largest time distance kept, seconds (default: 10% of the shutter)")
      ->check(CLI::PositiveNumber)->group(photonGroup);
  c->add_option("--kernel-footprint", a.kernelFootprint,
                "time method (twopass and 4d search): the space-time kernel of a caustic estimate seen from the camera is "
                "at least this many times one eye sample's share of its pixel (pixel area x shutter / spp), growing k_s "
                "(4d: k) up to 16x where photons "
                "bunch; 0: pure k-NN, whose tiny kernels at a focused moving caustic give speckles (default 1, "
                "docs/photon-map.md)")
      ->check(rangeOf(limits::kKernelFootprint))->group(photonGroup);
  c->add_option("--kernel-space", a.kernelSpace, "Space kernel: uniform, cone, epanechnikov (default uniform)")
      ->check(CLI::IsMember({"uniform", "cone", "epanechnikov"}))->group(photonGroup);
  c->add_option("--kernel-time", a.kernelTime, "Time kernel: uniform, epanechnikov (default uniform)")
      ->check(CLI::IsMember({"uniform", "epanechnikov"}))->group(photonGroup);
  c->add_option("--gather", a.gather, "Final-gather rays per sample for indirect light; 0: none (default 1)")
      ->check(rangeOf(limits::kGather))->group(photonGroup);
  c->add_flag("--global-direct", a.globalDirect, "Show the global photon map directly at the first diffuse hit (debugging, tests)")
      ->group(photonGroup);
  const std::string animationGroup = "Animations (scenes with an \"animation\" block, docs/animation.md)";
  c->add_option("--frame-range", a.frameRange, "Frames to render, A-B (from 0, inclusive) (default: all); with -o "
                "out/frame_####.exr each run of # becomes the zero-padded frame number (default <scene name>_####.exr), "
                "and the output directory is created")->group(animationGroup);
  c->add_option("--video", a.video, "Also assemble the frames' PNG previews into this .mp4 or .gif with ffmpeg "
                "(must be on PATH; checked before rendering)")->group(animationGroup);
  c->add_option("--window", a.window, "Frames whose photons are traced and held at once (default 4): memory stays "
                "bounded however many frames; --photons counts per frame's shutter time")
      ->check(CLI::Range(1, 100000))->group(animationGroup);
  c->add_flag("--independent-frames", a.independentFrames, "Seed every frame's photons independently (default: "
              "corresponding photon paths of every frame share random numbers, so still lighting does not flicker)")
      ->group(animationGroup);
  addProgressiveOptions(c, a);
  return c;
}

int runRender(const RenderArgs& a) {
  Timer total;
  // Under mpirun every rank loads and checks everything itself; an error on
  // any rank stops every rank before work starts, reported once
  // (dist::raiseIfAnyFailed). Rank 0 alone checks and writes the outputs,
  // prints progress, warnings and the summary.
  dist::Comm& comm = dist::world();
  const bool pbrtScene = pbrt::isPbrtPath(a.scene);
  std::string output = a.output.empty() ? stemOf(a.scene) + ".exr" : a.output;
  std::string preview = image::previewPathFor(output);
  scene::SceneDescription desc;
  RenderOptions opt;
  float exposure = 0.0f;
  std::unique_ptr<Scene> scene;
  std::string setupError;
  const bool framePattern = hasFramePlaceholder(a.output);
  try {
  if (a.method && !isRenderMethod(*a.method))
    throw Error("--method: unknown method '" + *a.method + "' (expected " + methodList() + ")");
  int width = 0, height = 0;
  if (a.resolution) parseResolution(*a.resolution, width, height);
  // A pbrt scene names its own output (Film "filename"), known only once it is read.
  // A frame pattern (out/frame_####.exr) is checked once the frames are known.
  if (comm.root() && (!pbrtScene || !a.output.empty()) && !framePattern) validateOutput(output, preview, a.scene);

  if (pbrtScene) {
    pbrt::ImportResult imported = pbrt::importPbrtFile(a.scene);
    if (comm.root())
      for (const std::string& n : imported.notes) std::fprintf(stderr, "tdpm: note: %s\n", n.c_str());
    if (a.output.empty()) {
      if (imported.filmFilename) output = exrNameForFilm(*imported.filmFilename);
      preview = image::previewPathFor(output);
      if (comm.root()) validateOutput(output, preview, a.scene);
    }
    desc = std::move(imported.scene);
  } else {
    desc = scene::loadScene(a.scene);
  }
  dist::testFailurePoint(comm, "load");
  if (a.kappa) {
    // The usable kappa depends on the scene's shutter (scene/limits.h).
    const double shutterLength = desc.animation ? desc.animation->shutterLength()
                                                : double(desc.camera.shutterClose) - desc.camera.shutterOpen;
    limits::KappaRange r = limits::kappaRange(shutterLength);
    if (!(*a.kappa >= r.lo && *a.kappa <= r.hi)) {
      char msg[200];
      std::snprintf(msg, sizeof msg, "--kappa: %g cannot be used with the %g s shutter of ", double(*a.kappa),
                    shutterLength);
      throw Error(msg + a.scene + ": the 4D metric needs kappa in [" + formatG(r.lo) + ", " + formatG(r.hi) +
                  "] (float range)");
    }
  }
  if (comm.root())
    for (const scene::ObjectDesc& o : desc.objects)
      if (o.shape.type == scene::ShapeDesc::Type::Mesh)
        refuseOverwritingInput(output, preview, o.shape.meshFile, "the mesh file of object '" + o.name + "'");
  opt = mergeOptions(a, desc.render, a.scene);
  // Passes by default where they are available: not for an animation's frames.
  mergeProgressiveOptions(a, desc.render, a.scene, opt, !desc.animation, comm.root());
  checkResumeFlags(a.resume ? &*a.resume : nullptr, opt.progressive);
  exposure = pick(a.exposure, desc.render.exposure, 0.0f);
  if (a.resolution) {
    desc.camera.width = width;
    desc.camera.height = height;
    opt.resolutionSource = "--resolution " + *a.resolution;
  } else {
    opt.resolutionSource = "camera.resolution in " + a.scene;
  }
  scene = Scene::build(desc);
  } catch (const Error& e) {
    if (!comm.distributed()) throw;
    setupError = e.what();
  }
  dist::raiseIfAnyFailed(comm, setupError);

  // A progressive render starts from the state --resume names (checked
  // against this scene and these options before any work) or from an empty
  // one with this render's fingerprint (cli/resume.h); the pass loop
  // updates it and the output EXR carries it (docs/resume.md).
  ProgressiveState progressiveState;
  if (opt.progressive) {
    // Not yet run per frame (every rank sees the same scene: an agreed error).
    if (desc.animation)
      throw dist::AgreedError("--progressive: an animation's frames are rendered with a fixed photon budget; progressive frames are "
                  "not supported yet (leave out --progressive, or render.progressive in " + a.scene + ")");
    // Under mpirun rank 0 alone reads --resume and holds the state; the
    // pass loop sends the others what they need (render/progressive.h).
    std::string resumeError;
    try {
      if (comm.root()) progressiveState = initialProgressiveState(a.resume ? &*a.resume : nullptr, desc, opt);
    } catch (const Error& e) {
      if (!comm.distributed()) throw;
      resumeError = e.what();
    }
    dist::raiseIfAnyFailed(comm, resumeError);
  }

  if (desc.animation) return runAnimation(a, desc, opt, exposure);
  if (framePattern || a.frameRange || a.video || a.window || a.independentFrames)
    throw Error(std::string(framePattern ? "--output: a frame-number pattern (#)"
                            : a.frameRange ? "--frame-range"
                            : a.video      ? "--video"
                            : a.window     ? "--window"
                                           : "--independent-frames") +
                " needs an animation, but " + a.scene + " has no \"animation\" block (docs/scene-format.md)");

  ThreadLimit limit(a.threads);
  // Under mpirun a rank's stderr is a pipe even on a terminal, but Open MPI
  // gives its stdout a pty when mpirun's own output is a terminal: that
  // decides for rank 0 (the bar still draws on stderr).
  bool showBar = ProgressBar::shouldShow(a.quiet) || (comm.distributed() && !a.quiet && isatty(STDOUT_FILENO) == 1);
  ProgressBar bar(comm.root() && showBar);
  if (comm.root())
    for (const std::string& w : accumulationSppWarnings(opt, scene->hasMotion))
      std::fprintf(stderr, "tdpm: warning: %s\n", w.c_str());
  RenderStats stats;
  // Progressive: the first SIGINT/SIGTERM/SIGHUP/SIGUSR1 ends the loop after the
  // current pass and the passes done are written; a second one aborts. Under
  // mpirun all but SIGUSR1 drop the round in flight (render/progressive.cpp).
  if (opt.progressive) signals::setMode(signals::Mode::Stop);
  signals::setStopNotice(comm.root());
  bool passLines = opt.progressive && !a.quiet && !ProgressBar::shouldShow(a.quiet);
  Film film = opt.progressive ? renderProgressive(*scene, opt, progressiveState,
                                                  passLines ? withPassLines(bar.progress()) : bar.progress(), stats,
                                                  comm)
                              : render(*scene, opt, bar.progress(), stats, comm);
  bar.finish();
  // --stats: every rank's communication, gathered before rank 0 writes.
  std::vector<RankSeconds> ranks = gatherRankStats(comm, stats.seconds);
  if (!comm.root()) return 0;
  for (const std::string& w : stats.warnings) std::fprintf(stderr, "tdpm: warning: %s\n", w.c_str());
  warnAccumulationPhotons(opt, scene->hasMotion, stats);

  const int filmWidth = film.width, filmHeight = film.height;
  image::ExrFile exr = filmToExr(std::move(film));  // moved: the write path holds no second film
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
                  {"tdpm/filter", filterName(opt.filter)},
                  {"tdpm/max_depth", std::to_string(opt.maxDepth)},
                  {"tdpm/render_seconds", seconds}};
  bool photonMethod = opt.method != "pathtrace";
  if (!photonMethod) exr.metadata["tdpm/caustic_guiding"] = formatG(opt.causticGuiding);
  if (photonMethod) {
    exr.metadata["tdpm/caustic_photons"] = std::to_string(stats.causticStored);
    exr.metadata["tdpm/global_photons"] = std::to_string(stats.globalStored);
    if (opt.method == "time") exr.metadata["tdpm/search"] = opt.spaceTime4D ? "4d" : "twopass";
    if (opt.method == "accumulation" && !opt.progressive) exr.metadata["tdpm/frames"] = std::to_string(opt.frames);
    if (opt.progressive) addProgressiveMetadata(progressiveState, exr.metadata);
  }
  // The state a later --resume continues from rides in the EXR (docs/resume.md).
  const int passesDone = progressiveState.passesDone;
  const std::string progressiveSummaryText = opt.progressive ? progressiveSummary(progressiveState) : std::string();
  if (opt.progressive) addProgressiveState(std::move(progressiveState), exr);
  writeRenderOutputs(output, preview, exr, exposure);  // both files or neither
  stats.peakResidentBytes = peakResidentBytes();      // --stats: the write path included

  if (!a.quiet) {
    std::string ranksNote = comm.distributed() ? " on " + std::to_string(comm.size()) + " ranks" : std::string();
    std::fprintf(stderr, "tdpm: %s, %s%s: %dx%d, %s camera samples (%d-%d per pixel), %.2f s in all -> %s (preview %s)\n",
                 a.scene.c_str(), opt.method.c_str(), ranksNote.c_str(), filmWidth, filmHeight,
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
  if (!progressiveSummaryText.empty() && !a.quiet)
    std::fprintf(stderr, "tdpm: progressive: %s\n", progressiveSummaryText.c_str());
  if (int sig = signals::stopRequested())
    std::fprintf(stderr, "tdpm: stopped by %s after pass %d: wrote the %d passes done to %s\n",
                 sig == SIGINT    ? "SIGINT"
                 : sig == SIGTERM ? "SIGTERM"
                 : sig == SIGHUP  ? "SIGHUP"
                 : sig == SIGUSR1 ? "SIGUSR1"
                                  : "a signal",
                 passesDone, passesDone, output.c_str());
  if (a.stats) {
    printStats(stats);
    printRankStats(ranks);
  }
  return 0;
}

}  // namespace tdpm::cli
