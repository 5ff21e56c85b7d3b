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
#include <set>
#include <sstream>
#include <vector>

#include "cli/animation_command.h"
#include "cli/flag_ranges.h"
#include "cli/frame_pattern.h"
#include "cli/path_names.h"
#include "cli/progress_bar.h"
#include "cli/rank_agreement.h"
#include "cli/render_metadata.h"
#include "cli/resume.h"
#include "render/progressive_io.h"
#include "cli/progressive_options.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/signals.h"
#include "core/memory.h"
#include "core/timer.h"
#include "distributed/comm.h"
#include "image/exr.h"
#include "image/png.h"
#include "import/pbrt_import.h"
#include "photon/store.h"
#include "render/animation.h"
#include "render/film_output.h"
#include "render/progressive.h"
#include "render/renderer.h"
#include "render/threads.h"
#include "scene/build_media.h"
#include "scene/limits.h"
#include "scene/parse.h"
#include "scene/scene.h"

namespace tdpm::cli {

namespace {

namespace limits = scene::limits;
static_assert(limits::kTimeBins == photon::kTimeBins, "the kappa range in scene/limits.h assumes the photon time bins");

std::string methodList() { return renderMethodList(); }

// A default value for a flag's help text (1, 0.25).
std::string shortNumber(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
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
  for (MapKind k : kAllMapKinds)
    if (mapKindReported(k, st.maps[k]))
    std::fprintf(stderr, "  %s photons: %llu stored, %llu emitted\n", mapKindName(k), u(st.maps[k].stored),
                 u(st.maps[k].emitted));
  if (st.guideStored > 0)
    std::fprintf(stderr, "  caustic guide: %llu stored, %llu emitted, %s reserved, %.3f s; cache %llu of %llu sub-cells filled\n",
                 u(st.guideStored), u(st.guideEmitted), formatMiB(st.guideBytes).c_str(), st.guideSeconds,
                 u(st.guideCellsFilled), u(st.guideCells));
  std::fprintf(stderr, "  photon pass: %.3f s\n", st.photonSeconds);
  std::fprintf(stderr, "  render: %.3f s\n", std::max(0.0, st.seconds - st.photonSeconds));
  std::fprintf(stderr, "  estimates: %llu time-dependent, %llu standard\n", u(st.timeEstimates),
               u(st.standardEstimates));
  // Issue 24: where an estimate reads few photons it is noisy (and was biased).
  std::string few;
  uint64_t knn = 0;
  for (MapKind k : kAllMapKinds) {
    if (!mapKindReported(k, st.maps[k])) continue;
    few += std::string(few.empty() ? "" : ", ") + mapKindName(k) + " " + std::to_string(st.maps[k].fewEstimates) +
           " of " + std::to_string(st.maps[k].estimates);
    knn += st.maps[k].estimates;
  }
  if (knn > 0) std::fprintf(stderr, "  estimates from fewer than %d photons: %s\n", estimate::kFewPhotons, few.c_str());
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

// render.photons_per_pixel (pbrt's sppm photonsperiteration -1): the
// caustic photon count from the resolution actually rendered (desc's camera,
// after --resolution), unless --photons gives one.
void applyPhotonsPerPixel(const RenderArgs& a, const scene::SceneDescription& desc,
                          const std::map<std::string, std::string>& settingSources, RenderOptions& o) {
  const std::optional<int64_t>& ppp = desc.render.photonsPerPixel;
  if (a.photons || !ppp) return;
  const int64_t pixels = int64_t(desc.camera.width) * desc.camera.height;
  auto it = settingSources.find("photons");
  std::string source = it != settingSources.end() ? it->second : "render.photons_per_pixel in " + a.scene;
  if (*ppp > limits::kPhotons.hi / pixels)
    throw Error(source + ": " + std::to_string(*ppp) + " photons per pixel x " + std::to_string(desc.camera.width) + "x" +
                std::to_string(desc.camera.height) + " pixels is more than tdpm's limit of " +
                std::to_string(limits::kPhotons.hi) + " photons");
  o.causticPhotons = size_t(*ppp * pixels);
  o.causticPhotonsSource = source + " (" + std::to_string(*ppp) + " x " + std::to_string(desc.camera.width) + "x" +
                           std::to_string(desc.camera.height) + " pixels)";
}

// Merges flags over the scene's settings over the renderer's defaults.
// `media`: the scene has participating media (scene::usesMedia), so a
// volume map is traced; without them --volume-photons has no map to fill.
RenderOptions mergeOptions(const RenderArgs& a, const scene::RenderSettings& sc, const std::string& sourcePath,
                           bool media) {
  RenderOptions o;
  // Both names were checked (runRender, scene/parse): this is the one parse.
  const std::string methodName = pick(a.method, sc.method, std::string(renderMethodName(o.method)));
  if (std::optional<RenderMethod> m = parseRenderMethod(methodName)) o.method = *m;
  else throw Error("--method: unknown method '" + methodName + "' (expected " + methodList() + ")");
  o.spp = pick(a.spp, sc.spp, o.spp);
  o.maxSpp = pick(a.maxSpp, sc.maxSpp, o.spp);
  o.contrast = pick(a.contrast, sc.contrast, o.contrast);
  o.seed = a.seed ? uint64_t(*a.seed) : sc.seed.value_or(o.seed);
  parseSamplerKind(pick(a.sampler, sc.sampler, std::string(samplerName(o.sampler))), o.sampler);  // both checked already
  parseFilterKind(pick(a.filter, sc.filter, std::string(filterName(o.filter))), o.filter);
  o.filterRadius = pick(a.filterRadius, sc.filterRadius, o.filterRadius);
  o.maxDepth = pick(a.maxDepth, sc.maxDepth, o.maxDepth);
  o.directOnly = sc.directOnly.value_or(false);
  if (o.directOnly && o.method != RenderMethod::PathTrace)
    throw Error("render.direct_only in " + sourcePath + " is a pathtrace setting, but the method is " +
                renderMethodName(o.method) + (a.method ? " (--method)" : ""));
  // A direct-only path never reaches a caustic: no guide photons to trace.
  if (o.directOnly && !a.causticGuiding) o.causticGuiding = 0.0f;
  o.causticGuiding = a.causticGuiding.value_or(o.causticGuiding);
  o.causticPhotons = size_t(pick(a.photons, sc.photons, int64_t(o.causticPhotons)));
  o.globalPhotons = size_t(pick(a.globalPhotons, sc.globalPhotons, int64_t(o.globalPhotons)));
  if (media)
    o.volumePhotons = size_t(pick(a.volumePhotons, sc.volumePhotons, int64_t(RenderOptions::kDefaultVolumePhotons)));
  o.frames = pick(a.frames, sc.frames, o.frames);
  o.spaceTime4D = pick(a.search, sc.search, std::string("twopass")) == "4d";
  o.estimate.k = pick(a.k, sc.k, o.estimate.k);
  o.estimate.ks = o.estimate.k;  // the two-pass search takes k in space, keeps f*k in time
  o.volumeK = a.volumeK.value_or(o.volumeK);
  o.estimate.fraction = pick(a.fraction, sc.fraction, o.estimate.fraction);
  o.kappa = pick(a.kappa, sc.kappa, o.kappa);
  if (a.maxRadius || sc.maxRadius) o.estimate.maxRadius = pick(a.maxRadius, sc.maxRadius, 0.0f);
  if (a.maxDt || sc.maxDt) o.estimate.maxTimeDistance = pick(a.maxDt, sc.maxDt, 0.0f);
  if (a.kernelFootprint) o.kernelFootprint = *a.kernelFootprint;
  o.estimate.spaceKernel = spaceKernelFrom(pick(a.kernelSpace, sc.kernelSpace, std::string("uniform")));
  o.estimate.timeKernel = timeKernelFrom(pick(a.kernelTime, sc.kernelTime, std::string("uniform")));
  o.gatherRays = pick(a.gather, sc.gather, o.gatherRays);
  if (a.gatherGuide) o.gatherGuide = *a.gatherGuide == "on";
  o.visualizeGlobal = a.globalDirect;
  // For the memory-budget error: name what set each count.
  if (!a.photons && sc.photons) o.causticPhotonsSource = "render.photons in " + sourcePath;
  if (!a.globalPhotons && sc.globalPhotons) o.globalPhotonsSource = "render.global_photons in " + sourcePath;
  if (!a.volumePhotons && sc.volumePhotons) o.volumePhotonsSource = "render.volume_photons in " + sourcePath;
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
  // A progressive accumulation renders one time per pass, not frames (issue
  // 27 item 16: it warned of "8 frames" while 2 passes took 2 spp).
  if (!renderMethodTraits(o.method).inBetweenFrames || o.progressive || !hasMotion || o.frames <= 1) return w;
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
  if (!renderMethodTraits(o.method).inBetweenFrames || o.progressive) return;
  const int frames = hasMotion ? std::max(1, o.frames) : 1;
  auto check = [&](const char* kind, size_t asked, size_t stored) {  // per map kind
    if (asked > 0 && double(stored) > 1.1 * double(asked))
      std::fprintf(stderr,
                   "tdpm: warning: accumulation: %s %s photons stored, not the %s asked for: each of the %d frames "
                   "traces at least one batch of photon paths (fewer --frames or more photons avoid it)\n",
                   formatCount(stored).c_str(), kind, formatCount(asked).c_str(), frames);
  };
  for (MapKind k : kAllMapKinds) check(mapKindName(k), o.*mapKindInfo(k).photons, st.maps[k].stored);
}

}  // namespace

RenderOptions renderOptionsFor(const RenderArgs& a, const scene::SceneDescription& desc) {
  RenderOptions o = mergeOptions(a, desc.render, a.scene, scene::usesMedia(desc));
  applyPhotonsPerPixel(a, desc, {}, o);
  return o;
}

// The flag table, one statement per flag in --help order: longer than 80
// lines on purpose (it holds no logic; splitting it would only scatter the
// help text).
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
                 "--exposure may change. --output may name the same file: it is replaced atomically (docs/resume.md). "
                 "An animation: a frame pattern, each frame continued from its own file (docs/animation.md)");
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
  c->add_option("--volume-photons", a.volumePhotons,
                "Volume photons to store, at scattering events in participating media (default 100000 when the scene "
                "has media; no volume map otherwise)")
      ->check(rangeOf(limits::kPhotons))->group(photonGroup);
  c->add_option("--frames", a.frames, "accumulation: in-between frames, each with 1/N of the photons and of the samples (default 8); every "
                "frame takes at least 1 sample per pixel and one batch of photon paths, so frames above --spp or "
                "far above the photon counts raise the totals (a warning says so)")
      ->check(rangeOf(limits::kFrames))->group(photonGroup);
  c->add_option("--search", a.search, "time: twopass (space, then time) or 4d (space-time kd-tree) (default twopass)")
      ->check(CLI::IsMember({"twopass", "4d"}))->group(photonGroup);
  c->add_option("--k", a.k, "Photons in the spatial search: k for standard and 4d, k_s for twopass (default 100)")
      ->check(rangeOf(limits::kK))->group(photonGroup);
  c->add_option("--volume-k", a.volumeK,
                "Scenes with media: each volume photon's beam disc is its distance to its k-th nearest volume photon, "
                "and its time window the fraction --fraction nearest in time of those k (default 32 with a fixed budget, "
                "--k with --progressive; docs/media.md, "
                "\"The beam query's cost\")")
      ->check(rangeOf(limits::kVolumeK))->group(photonGroup);
  c->add_option("--fraction", a.fraction, "twopass: fraction of the k_s kept nearest in time (default 0.5)")
      ->check(rangeOf(limits::kFraction))->group(photonGroup);
  c->add_option("--kappa", a.kappa, "4d: weight of time in the metric d^2 = |dx|^2 + kappa dt^2 (default 1; for a 1 s shutter at least 7.704e-34 and at most 8.507e37, see docs/scene-format.md)")
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
  c->add_option("--gather-guide", a.gatherGuide,
                "Fixed budget: each final-gather ray is a pair, one BSDF-sampled and one aimed along the incoming "
                "direction of one of the 32 global photons nearest the gather point (Jensen 1995; balance heuristic, "
                "unbiased): a bright patch beside a lamp no longer salts a large room (sparse-room: salt 0.82% -> "
                "0.04%); no cone toward a light; not used under a non-black background, whose light has no photons; "
                "on or off (default on; docs/photon-map.md)")
      ->check(CLI::IsMember({"on", "off"}))->group(photonGroup);
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
  c->add_option("--shared-photons", a.sharedPhotons, "Time-invariant photons (paths from still lights that miss "
                "everything moving) traced once per block of --window frames, with this many times one frame's "
                "paths, and used by every frame of the block; 0: none shared (default "
                + shortNumber(AnimationOptions{}.sharedScale) + ")")
      ->check(CLI::Range(0.0, 1000.0))->group(animationGroup);
  c->add_option("--moving-photons", a.movingPhotons, "With --shared-photons: each frame traces this many times its "
                "paths for the photons whose path meets motion (default " + shortNumber(AnimationOptions{}.movingScale) + ")")
      ->check(CLI::Range(0.001, 1000.0))->group(animationGroup);
  CLI::Option* cont = c->add_flag("--continue-paths", a.continuePaths,
              "With --shared-photons: each frame continues the block's photon paths that meet motion from their "
              "last time-invariant vertex instead of tracing its paths from the light (default: " +
                  std::string(AnimationOptions{}.continuePaths ? "on" : "off") + "; docs/animation.md section 8)")
      ->group(animationGroup);
  c->add_flag("--no-continue-paths", a.noContinuePaths, "With --shared-photons: every frame traces its paths from the light")
      ->excludes(cont)->group(animationGroup);
  addProgressiveOptions(c, a);
  return c;
}

namespace {

// What a render needs once its input is read and checked: the output names,
// the scene (description and built), the merged options and the exposure.
struct RenderSetup {
  std::string output, preview;
  scene::SceneDescription desc;
  RenderOptions opt;
  float exposure = 0.0f;
  std::unique_ptr<Scene> scene;
};

// --kappa against the scene's shutter (the usable range depends on it,
// scene/limits.h).
void checkKappa(const RenderArgs& a, const scene::SceneDescription& desc) {
  if (!a.kappa) return;
  const double shutterLength = desc.animation ? desc.animation->shutterLength()
                                              : double(desc.camera.shutterClose) - desc.camera.shutterOpen;
  limits::KappaRange r = limits::kappaRange(shutterLength);
  if (!(*a.kappa >= r.lo && *a.kappa <= r.hi)) {
    char msg[200];
    std::snprintf(msg, sizeof msg, "--kappa: %g cannot be used with the %g s shutter of ", double(*a.kappa),
                  shutterLength);
    throw Error(msg + a.scene + ": the 4D metric needs kappa in [" + limits::boundText(r.lo, true, true) + ", " +
                limits::boundText(r.hi, false, true) + "] (float range)");
  }
}

// Reads the scene (JSON or pbrt), checks every flag and the output location
// before any work, merges the options and builds the scene. Throws
// tdpm::Error; every rank runs it (rank 0 alone checks the outputs).
void loadRenderSetup(const RenderArgs& a, dist::Comm& comm, bool framePattern, RenderSetup& s) {
  const bool pbrtScene = pbrt::isPbrtPath(a.scene);
  if (a.method && !parseRenderMethod(*a.method))
    throw Error("--method: unknown method '" + *a.method + "' (expected " + methodList() + ")");
  int width = 0, height = 0;
  if (a.resolution) parseResolution(*a.resolution, width, height);
  // A pbrt scene names its own output (Film "filename"), known only once it is read.
  // A frame pattern (out/frame_####.exr) is checked once the frames are known.
  if (comm.root() && (!pbrtScene || !a.output.empty()) && !framePattern) validateOutput(s.output, s.preview, a.scene);

  std::map<std::string, std::string> settingSources;  // pbrt: where derived render settings came from
  if (pbrtScene) {
    pbrt::ImportResult imported = pbrt::importPbrtFile(a.scene);
    if (comm.root())
      for (const std::string& n : imported.notes) std::fprintf(stderr, "tdpm: note: %s\n", n.c_str());
    if (a.output.empty()) {
      if (imported.filmFilename) s.output = exrNameForFilm(*imported.filmFilename);
      s.preview = image::previewPathFor(s.output);
      if (comm.root()) validateOutput(s.output, s.preview, a.scene);
    }
    // An Include or PLY mesh named like the output is an input too.
    if (comm.root() && !framePattern)
      for (const std::string& f : std::set<std::string>(imported.inputFiles.begin(), imported.inputFiles.end()))
        refuseOverwritingInput(s.output, s.preview, f, "a file the scene reads");
    s.desc = std::move(imported.scene);
    settingSources = std::move(imported.settingSources);
  } else {
    s.desc = scene::loadScene(a.scene);
  }
  dist::testFailurePoint(comm, "load");
  checkKappa(a, s.desc);
  if (comm.root())
    for (const scene::ObjectDesc& o : s.desc.objects)
      if (o.shape.type == scene::ShapeDesc::Type::Mesh)
        refuseOverwritingInput(s.output, s.preview, o.shape.meshFile, "the mesh file of object '" + o.name + "'");
  s.opt = mergeOptions(a, s.desc.render, a.scene, scene::usesMedia(s.desc));
  // A pbrt scene's photon count comes from a statement, not a JSON key.
  if (!a.photons && settingSources.count("photons")) s.opt.causticPhotonsSource = settingSources["photons"];
  // Passes by default where they are available: not for an animation's
  // frames, and not in media, where the passes' volume kernels start wide
  // and converge slowly (docs/media.md "Progressive passes in media": the
  // airlight test scene 17% low after 8 passes; fixed-budget fog-airlight
  // within 2%); --progressive still asks for them.
  mergeProgressiveOptions(a, s.desc.render, a.scene, s.opt, !s.desc.animation && !scene::usesMedia(s.desc),
                          comm.root());
  checkResumeFlags(a.resume ? &*a.resume : nullptr, s.opt.progressive);
  s.exposure = pick(a.exposure, s.desc.render.exposure, 0.0f);
  if (a.resolution) {
    s.desc.camera.width = width;
    s.desc.camera.height = height;
    s.opt.resolutionSource = "--resolution " + *a.resolution;
  } else {
    s.opt.resolutionSource = "camera.resolution in " + a.scene;
  }
  applyPhotonsPerPixel(a, s.desc, settingSources, s.opt);
  s.scene = Scene::build(s.desc);
}

// A progressive render starts from the state --resume names (checked
// against this scene and these options before any work) or from an empty
// one with this render's fingerprint (cli/resume.h); the pass loop
// updates it and the output EXR carries it (docs/resume.md).
ProgressiveState startProgressiveState(const RenderArgs& a, const RenderSetup& s, dist::Comm& comm) {
  ProgressiveState state;
  if (!s.opt.progressive) return state;
  // An animation's progressive frames each have a state of their own, one
  // file per frame (cli/animation_command.cpp reads --resume as a frame
  // pattern).
  if (s.desc.animation) return state;
  // Under mpirun rank 0 alone reads --resume and holds the state; the
  // pass loop sends the others what they need (render/progressive.h).
  std::string resumeError;
  try {
    if (comm.root()) state = initialProgressiveState(a.resume ? &*a.resume : nullptr, s.desc, s.opt);
  } catch (const Error& e) {
    if (!comm.distributed()) throw;
    resumeError = e.what();
  }
  dist::raiseIfAnyFailed(comm, resumeError);
  return state;
}

// The animation flags on a scene without an animation block.
void refuseAnimationFlags(const RenderArgs& a, bool framePattern) {
  if (framePattern || a.frameRange || a.video || a.window || a.independentFrames || a.sharedPhotons || a.movingPhotons ||
      a.continuePaths || a.noContinuePaths)
    throw Error(std::string(framePattern ? "--output: a frame-number pattern (#)"
                            : a.frameRange ? "--frame-range"
                            : a.video      ? "--video"
                            : a.window     ? "--window"
                            : a.sharedPhotons ? "--shared-photons"
                            : a.movingPhotons ? "--moving-photons"
                            : a.continuePaths ? "--continue-paths"
                            : a.noContinuePaths ? "--no-continue-paths"
                                           : "--independent-frames") +
                " needs an animation, but " + a.scene + " has no \"animation\" block (docs/scene-format.md)");
}

// The render itself, fixed budget or progressive, with the progress bar
// (rank 0) and the stop signals of a progressive render.
Film renderImage(const RenderArgs& a, const RenderSetup& s, ProgressiveState& state, RenderStats& stats,
                 dist::Comm& comm) {
  const RenderOptions& opt = s.opt;
  // Under mpirun no bar (ProgressBar::stream): a rank's stdout is a pty
  // whatever mpirun's output is, so the bar went into redirected logs;
  // progressive renders print a line per pass instead.
  std::FILE* barStream = ProgressBar::stream(a.quiet, comm.distributed());
  ProgressBar bar(comm.root() && barStream, barStream ? barStream : stderr);
  if (comm.root())
    for (const std::string& w : accumulationSppWarnings(opt, s.scene->hasMotion))
      std::fprintf(stderr, "tdpm: warning: %s\n", w.c_str());
  // Progressive: the first SIGINT/SIGTERM/SIGHUP/SIGUSR1 ends the loop after the
  // current pass and the passes done are written; a second one aborts. Under
  // mpirun all but SIGUSR1 drop the round in flight (render/progressive.cpp).
  if (opt.progressive) signals::setMode(signals::Mode::Stop);
  signals::setStopNotice(comm.root());
  bool passLines = opt.progressive && !a.quiet && !barStream;
  Film film = opt.progressive ? renderProgressive(*s.scene, opt, state,
                                                  passLines ? withPassLines(bar.progress()) : bar.progress(), stats,
                                                  comm)
                              : render(*s.scene, opt, bar.progress(), stats, comm);
  bar.finish();
  return film;
}

// Rank 0's lines after the image is written: the summary, the photons, the
// progressive passes, a stop by a signal, and --stats.
void printRenderSummary(const RenderArgs& a, const RenderSetup& s, const RenderStats& stats, int filmWidth,
                        int filmHeight, double totalSeconds, const std::string& progressiveSummaryText, int passesDone,
                        const std::vector<RankSeconds>& ranks, int rankCount) {
  if (!a.quiet) {
    std::string ranksNote = rankCount > 1 ? " on " + std::to_string(rankCount) + " ranks" : std::string();
    std::fprintf(stderr, "tdpm: %s, %s%s: %dx%d, %s camera samples (%d-%d per pixel), %.2f s in all -> %s (preview %s)\n",
                 a.scene.c_str(), renderMethodName(s.opt.method), ranksNote.c_str(), filmWidth, filmHeight,
                 formatCount(stats.cameraSamples).c_str(), stats.minSpp, stats.maxSpp, totalSeconds, s.output.c_str(),
                 s.preview.c_str());
    if (renderMethodTraits(s.opt.method).photonMaps) {
      std::string maps;  // "N caustic (M emitted), ..." in kind order
      for (MapKind k : kAllMapKinds)
        if (mapKindReported(k, stats.maps[k]))
        maps += (maps.empty() ? "" : ", ") + formatCount(stats.maps[k].stored) + " " + mapKindName(k) + " (" +
                formatCount(stats.maps[k].emitted) + " emitted)";
      std::fprintf(stderr, "tdpm: photons: %s, %.1f bytes each, %.2f s; estimates: %llu time-dependent, %llu standard\n",
                   maps.c_str(), stats.bytesPerPhoton, stats.photonSeconds,
                   static_cast<unsigned long long>(stats.timeEstimates),
                   static_cast<unsigned long long>(stats.standardEstimates));
    }
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
                 passesDone, passesDone, s.output.c_str());
  if (a.stats) {
    printStats(stats);
    printRankStats(ranks);
  }
}

}  // namespace

// One level: set-up (every rank, errors agreed), the animation or the one
// image, rank 0's outputs and summary.
int runRender(const RenderArgs& a) {
  Timer total;
  // Under mpirun every rank loads and checks everything itself; an error on
  // any rank stops every rank before work starts, reported once
  // (dist::raiseIfAnyFailed). Rank 0 alone checks and writes the outputs,
  // prints progress, warnings and the summary.
  dist::Comm& comm = dist::world();
  RenderSetup s;
  s.output = a.output.empty() ? stemOf(a.scene) + ".exr" : a.output;
  s.preview = image::previewPathFor(s.output);
  std::string setupError;
  const bool framePattern = hasFramePlaceholder(a.output);
  try {
    loadRenderSetup(a, comm, framePattern, s);
  } catch (const Error& e) {
    if (!comm.distributed()) throw;
    setupError = e.what();
  }
  dist::raiseIfAnyFailed(comm, setupError);
  // Under mpirun: the same scene and options on every rank, or one error
  // before any collective whose shape depends on them (cli/rank_agreement.h).
  requireRanksAgree(comm,
                    comm.distributed() ? rankSettings(a, s.desc, s.opt, s.exposure) : std::map<std::string, std::string>{},
                    a.scene);
  ProgressiveState progressiveState = startProgressiveState(a, s, comm);

  if (s.desc.animation) return runAnimation(a, s.desc, s.opt, s.exposure);
  refuseAnimationFlags(a, framePattern);

  ThreadLimit limit(a.threads);
  RenderStats stats;
  Film film = renderImage(a, s, progressiveState, stats, comm);
  // --stats: every rank's communication, gathered before rank 0 writes.
  std::vector<RankSeconds> ranks = gatherRankStats(comm, stats.seconds);
  if (!comm.root()) return 0;
  for (const std::string& w : stats.warnings) std::fprintf(stderr, "tdpm: warning: %s\n", w.c_str());
  warnAccumulationPhotons(s.opt, s.scene->hasMotion, stats);

  const int filmWidth = film.width, filmHeight = film.height;
  image::ExrFile exr = filmToExr(std::move(film));  // moved: the write path holds no second film
  exr.metadata = renderMetadata(a.scene, s.opt, stats);
  if (renderMethodTraits(s.opt.method).photonMaps && s.opt.progressive)
    addProgressiveMetadata(progressiveState, exr.metadata);
  // The state a later --resume continues from rides in the EXR (docs/resume.md).
  const int passesDone = progressiveState.passesDone;
  const std::string progressiveSummaryText = s.opt.progressive ? progressiveSummary(progressiveState) : std::string();
  if (s.opt.progressive) addProgressiveState(std::move(progressiveState), exr);
  writeRenderOutputs(s.output, s.preview, exr, s.exposure);  // both files or neither
  stats.peakResidentBytes = peakResidentBytes();              // --stats: the write path included
  printRenderSummary(a, s, stats, filmWidth, filmHeight, total.seconds(), progressiveSummaryText, passesDone, ranks,
                     comm.distributed() ? comm.size() : 1);
  return 0;
}

}  // namespace tdpm::cli
