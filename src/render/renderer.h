// render/renderer.h — render(): one built scene + options -> a Film.
// Chooses the method once (path tracer, or photon maps + PhotonIntegrator),
// then runs the one tile loop with adaptive (sub-pixel, time) sampling.
#pragma once
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/progress.h"
#include "distributed/comm.h"
#include "estimate/estimators.h"
#include "motion/shutter.h"
#include "render/film.h"
#include "render/map_kinds.h"
#include "render/render_options.h"
#include "sampling/filter.h"
#include "sampling/sampler.h"
#include "scene/scene.h"

namespace tdpm {

struct PhotonMap;

// Adaptive sampling never stops a pixel before this many samples. A pixel
// whose value is carried by paths of probability q per sample misses all
// of them in its first N samples with probability (1 - q)^N; its
// neighbours, which decide when it stops (renderer.cpp), miss them in all
// 8 x 64 = 512 of theirs with probability (1 - q)^512: below 1% for
// q >= 0.9%. With fewer, a neighbourhood that has not yet met its caustic
// paths looks converged. The stopping decision is independent of the
// pixel's own samples, so this bounds how much is wasted, not the bias.
inline constexpr int kAdaptiveMinSamples = 64;
// Bytes per pixel the adaptive loop holds while a film is rendered
// (renderer.cpp checks it against its types): a pixel accumulator (56), its
// activity flag (1) and its half-buffer error (4).
inline constexpr uint64_t kSamplerBytesPerPixel = 61;

// What the user should know before looking at the image: no lights and a
// black background, lights of zero power (every render path reports them).
std::vector<std::string> sceneWarnings(const Scene& scene);

// A located error when the scene has participating media and the options
// ask for what does not render them: a still image (stillImage, render())
// takes every method (the photon methods' eye side in media:
// render/photon_integrator_media.cpp), progressive time and standard, not
// progressive accumulation; animations and their frames pathtrace, time and
// standard, fixed budget and progressive.
// render(), renderFrame() and renderAnimation() call it first.
void checkMediaSupport(const Scene& scene, const RenderOptions& options, bool stillImage = false);


// Throws tdpm::Error, before any work, when the image and the photon maps
// the options ask for cannot fit in the machine's available memory
// (render/memory_budget.h checkMemoryBudget with MemAvailable).
// Distributed (comm.size() > 1, every rank calls it alike): photon batches
// and image tiles are split over the ranks, every rank gets the whole photon
// maps, and rank 0 alone returns the whole film (the others return their own
// tiles only); bit-identical to one process (docs/distributed.md).
Film render(const Scene& scene, const RenderOptions& options, const Progress& progress, RenderStats& stats,
            dist::Comm& comm = dist::local());

// One frame of an animation (render/animation.h): camera samples take
// times in `shutter` (scene seconds, inside the scene's shutter, which is
// the whole timeline) and photon methods (time, standard) use the given
// maps, whose standard trees hold only this frame's photons. No memory
// check (the caller made it). Where a progressive frame will call the
// progressive renderer with the same input.
struct FrameInput {
  Shutter shutter;
  PerMap<const PhotonMap*> maps;  // null for the path tracer
};
Film renderFrame(const Scene& scene, const RenderOptions& options, const FrameInput& frame, const Progress& progress,
                 RenderStats& stats);

}  // namespace tdpm
