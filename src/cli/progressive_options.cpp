// cli/progressive_options.cpp — see progressive_options.h.
#include "cli/progressive_options.h"

#include "cli/flag_ranges.h"

#include <cstdio>

#include "core/error.h"
#include "render/progressive.h"

namespace tdpm::cli {

namespace {
std::string g17(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}
}  // namespace

void addProgressiveOptions(CLI::App* c, RenderArgs& a) {
  const std::string group = "Progressive photon mapping (time, accumulation, standard)";
  c->add_flag("--progressive", a.progressive,
              "Render in passes, each with fresh photons and fixed kernels that shrink from pass to pass, averaged "
              "into the image: converges in the memory of one pass (docs/photon-map.md). Photon counts are per pass; "
              "--spp is the samples per pixel of each pass. Stops after --passes, or after the pass that reaches "
              "--time-limit (default: 30 s when neither is given); SIGINT/SIGTERM/SIGUSR1 stop after the current pass and "
              "write the passes done (under mpirun SIGINT/SIGTERM drop the round in flight, SIGUSR1 to mpirun lets it end). This is the default when a scene is rendered with its own photon method (its render.method, "
              "or time) and neither -m, --fixed-budget nor render.progressive says otherwise. Under mpirun each rank runs its own passes, one per rank per round, and the "
              "image equals one process's with the same passes (docs/distributed.md)")
      ->group(group);
  c->add_flag("--fixed-budget", a.fixedBudget,
              "Render with one photon budget, not in passes: overrides the default for a scene's own photon method "
              "and a render block's \"progressive\": true (its passes and time_limit are then not used)")
      ->excludes("--progressive")->group(group);
  c->add_option("--passes", a.passes, "--progressive: stop once this many passes are done (an animation: per frame)")
      ->check(rangeOf(scene::limits::kPasses))->group(group);
  c->add_option("--time-limit", a.timeLimit,
                "--progressive: stop after the pass that reaches this many seconds (under mpirun: after the round of "
                "passes that reaches it; an animation: per frame)")
      ->check(rangeOf(scene::limits::kTimeLimit))->group(group);
  c->add_option("--alpha", a.alpha,
                "--progressive: the kernel's shrink per pass, volume_{i+1} = volume_i (i + alpha)/(i + 1), in (0, 1) "
                "(default 4/7 for time's space-time kernel, 2/3 for the spatial kernel of accumulation and standard)")
      ->check(rangeOf(scene::limits::kAlpha))->group(group);
  c->add_option("--extra-samples", a.extraSamples,
                "--progressive: extra eye samples per pass, as a fraction of spp x pixels, given to the pixels whose "
                "eye paths an eye-only pilot (32 discarded samples per pixel, before pass 0) finds noisy: a "
                "motion-blurred highlight seen in glass, a moving shadow. Each pixel takes the same count in every "
                "pass, between --spp and --extra-cap x --spp, so the image stays unbiased and a resumed or mpirun "
                "render equals one run; the EXR's spp layer holds the real counts. 0: every pixel takes --spp "
                "(default " + formatG(kDefaultExtraSamples) + ")")
      ->check(rangeOf(kExtraSamplesRange))->group(group);
  c->add_option("--extra-cap", a.extraCap,
                "--progressive: a pixel takes at most this many times --spp eye samples per pass (default 32; "
                "1: no extra samples)")
      ->check(rangeOf(kExtraCapRange))->group(group);
}

void mergeProgressiveOptions(const RenderArgs& a, const scene::RenderSettings& sc, const std::string& sourcePath,
                             RenderOptions& o, bool defaultAllowed, bool printNotes) {
  // A scene's "progressive": true is for the photon methods it is meant for:
  // `-m pathtrace` (or static) on that scene renders as usual, without passes.
  // Nobody said: a scene rendered with its own photon method renders in passes.
  const bool byDefault = defaultAllowed && !a.method && !a.fixedBudget && !sc.progressive.has_value();
  const bool sceneAsks = !a.fixedBudget && sc.progressive.value_or(byDefault);
  const bool sceneApplies = sceneAsks && renderMethodTraits(o.method).progressive;
  o.progressive = a.progressive || sceneApplies;
  if (!o.progressive) {
    // --fixed-budget (or a method without passes) overrides a scene that asks
    // for passes: its pass keys go with it.
    const bool sceneKeysApply = !a.fixedBudget && !sceneAsks;
    if (a.passes) throw Error("--passes needs --progressive (a fixed-budget render has no passes)");
    if (a.timeLimit) throw Error("--time-limit needs --progressive (a fixed-budget render has no passes)");
    if (a.alpha) throw Error("--alpha needs --progressive (a fixed-budget render has no shrinking kernel)");
    if (a.extraSamples)
      throw Error("--extra-samples needs --progressive (a fixed-budget render samples adaptively with --max-spp)");
    if (a.extraCap) throw Error("--extra-cap needs --progressive (a fixed-budget render samples adaptively with --max-spp)");
    if (sc.passes && sceneKeysApply)
      throw Error("render.passes in " + sourcePath + " needs render.progressive true or --progressive");
    if (sc.timeLimit && sceneKeysApply)
      throw Error("render.time_limit in " + sourcePath + " needs render.progressive true or --progressive");
    return;
  }
  if (!renderMethodTraits(o.method).progressive)
    throw Error("--progressive works with the methods time, accumulation and standard, not '" +
                std::string(renderMethodName(o.method)) +
                "' (set by " + (a.method ? std::string("--method") : "render.method in " + sourcePath + " or the default") + ")");
  // Settings a progressive render does not use: a flag is an error (the
  // user asked for something that would not happen), a scene key a note
  // (the scene may be meant for fixed-budget renders too).
  auto unused = [&](bool flag, bool key, const char* flagName, const char* keyName, const char* why) {
    if (flag) throw Error(std::string(flagName) + " has no effect with --progressive (" + why + ")");
    if (key && printNotes)
      std::fprintf(stderr, "tdpm: note: render.%s in %s is not used by --progressive (%s)\n", keyName,
                   sourcePath.c_str(), why);
  };
  unused(a.maxSpp && *a.maxSpp > o.spp, sc.maxSpp && *sc.maxSpp > o.spp, "--max-spp", "max_spp",
         "every pass takes --spp samples per pixel, up to --extra-cap x --spp where the pilot finds noisy eye paths "
         "(--extra-samples); more passes take more");
  // Named by the method in use: -m time was told about "accumulation --progressive" (issue 27 item 16).
  unused(bool(a.frames), bool(sc.frames), "--frames", "frames",
         renderMethodTraits(o.method).inBetweenFrames
             ? "passes replace in-between frames: accumulation --progressive renders one stratified time per pass"
             : "only the accumulation method renders in-between frames");
  unused(a.search && *a.search == "4d", sc.search && *sc.search == "4d", "--search 4d", "search",
         "the passes gather with fixed kernels, not a k-NN search");
  unused(a.kernelSpace && *a.kernelSpace != "uniform", sc.kernelSpace && *sc.kernelSpace != "uniform",
         "--kernel-space", "kernel_space", "the fixed kernels are uniform");
  unused(a.kernelTime && *a.kernelTime != "uniform", sc.kernelTime && *sc.kernelTime != "uniform", "--kernel-time",
         "kernel_time", "the fixed kernels are uniform");
  unused(bool(a.kappa), bool(sc.kappa), "--kappa", "kappa", "it weighs the 4d search, which passes do not use");
  o.maxSpp = o.spp;
  if (a.passes) o.passes = *a.passes;
  else if (sc.passes) o.passes = *sc.passes;
  if (a.timeLimit) o.timeLimitSeconds = *a.timeLimit;
  else if (sc.timeLimit) o.timeLimitSeconds = double(*sc.timeLimit);
  // A flag that sets one limit replaces the scene's other one too.
  if ((a.passes || a.timeLimit) && !(a.passes && a.timeLimit)) {
    if (a.passes && !a.timeLimit) o.timeLimitSeconds = 0;
    if (a.timeLimit && !a.passes) o.passes = 0;
  }
  if (a.alpha) o.alpha = *a.alpha;
  o.passExtraSamples = a.extraSamples.value_or(kDefaultExtraSamples);
  if (a.extraCap) o.passSampleCap = *a.extraCap;
}

void addProgressiveMetadata(const ProgressiveState& s, std::map<std::string, std::string>& m) {
  m["tdpm/progressive"] = "1";
  m["tdpm/passes"] = std::to_string(s.passesDone);
  m["tdpm/photons_emitted"] = g17(s.totals.photonsEmitted);
  m["tdpm/photons_stored"] = g17(s.totals.photonsStored);
  m["tdpm/kernel_radius"] = g17(s.totals.kernelRadius);
  m["tdpm/kernel_spatial_radius"] = g17(s.totals.kernelSpatialRadius);
  m["tdpm/kernel_half_window"] = g17(s.totals.kernelHalfWindow);
  m["tdpm/progressive_seconds"] = g17(s.totals.seconds);
  auto a = s.settings.find("alpha");
  if (a != s.settings.end()) m["tdpm/alpha"] = a->second;
}

Progress withPassLines(Progress p) {
  auto previous = p.position;
  p.position = [previous](const WorkPosition& w) {
    if (previous) previous(w);
    if (w.done == 0) return;
    std::fprintf(stderr, "tdpm: pass %zu%s done, %.4g photon paths emitted in all\n", w.done,
                 w.total ? (" of " + std::to_string(w.total)).c_str() : "", double(w.photonsEmitted));
  };
  return p;
}

std::string progressiveSummary(const ProgressiveState& s) {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "%d passes, %.4g photons emitted (%.4g stored), final kernel radius %.4g (spatial %.4g), half window "
                "%.4g s, %.2f s of passes",
                s.passesDone, s.totals.photonsEmitted, s.totals.photonsStored, s.totals.kernelRadius,
                s.totals.kernelSpatialRadius, s.totals.kernelHalfWindow, s.totals.seconds);
  return buf;
}

}  // namespace tdpm::cli
