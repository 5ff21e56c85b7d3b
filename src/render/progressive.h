// render/progressive.h — progressive photon mapping in passes (issue 10,
// docs/photon-map.md "Progressive passes"). A render is a sequence of
// passes; pass i (0-based) traces fresh photon maps (global photon path
// indices continue those of passes 0..i-1), renders eye samples
// [i m_p, (i+1) m_p) of every pixel p (m_p = spp, or the pilot's count with
// opt.passExtraSamples > 0: render/sample_allocation.h) with kernels fixed for the pass
// (estimate/fixed_kernel.h), and adds the pixel means into running float
// sums: the image is their mean. Memory is one pass's, whatever the count.
//
// Variants (RenderOptions::method):
//   time          space-time kernel (disc r_i x window h_i) where an eye path
//                 meets motion, the spatial disc over the whole shutter
//                 elsewhere (the skip rule); volume shrinks by (i+a)/(i+1).
//   accumulation  pbrt-v4's PR #441: each pass at one stratified time (a
//                 rotated radical inverse of the pass index) for all its
//                 photons and eye samples, spatial disc, its own alpha.
//   standard      photons over the shutter, time ignored (the wrong baseline).
//
// Everything pass i depends on is in the ProgressiveState (pass 0's photon
// path counts and kernels) or a deterministic function of (options, scene,
// pass index), so a run of 2N passes and a run of N resumed for N more give
// bit-identical images; combining states is summation of their layers.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/progress.h"
#include "distributed/comm.h"
#include "estimate/fixed_kernel.h"
#include "render/film.h"
#include "render/photon_map.h"
#include "render/progressive_state.h"
#include "render/renderer.h"
#include "scene/scene.h"

namespace tdpm {

// Without --passes or --time-limit a progressive render stops after the pass
// that reaches this many seconds.
constexpr double kDefaultProgressiveSeconds = 30.0;

// The alphas (docs/photon-map.md): 4/(d+4) for a d-dimensional kernel.
constexpr float kAlphaSpaceTime = 4.0f / 7.0f;  // disc x window, d = 3
constexpr float kAlphaSpatial = 2.0f / 3.0f;    // disc, d = 2

// Both kernels (space-time, spatial) of each map for one pass.
using PassKernels = PerMap<estimate::MapKernel>;

// Relative size of pass `pass`'s (0-based) kernel to pass 0's, for a kernel
// of `dims` dimensions whose volume shrinks as V_{j+1} = V_j (j + a)/(j + 1)
// (j 1-based): (V_{pass+1} / V_1)^(1/dims). Deterministic (a double product).
double kernelScale(int pass, double alpha, int dims);

// The kernels of pass `pass` from pass 0's (state.pilot),
// with the half window floored at one photon time bin (shutter / 256; the
// volume schedule is then kept by the radius).
PassKernels kernelsForPass(const ProgressiveState& state, const RenderOptions& opt, const Scene& scene, int pass);

// The accumulation variant's time of pass `pass`, in [0, 1): a radical
// inverse of the pass index, rotated by a hash of the seed.
float accumulationPassTime(int pass, uint64_t seed);

// Where a pass's photon maps come from when not traced from the options
// (the pass's path range): progressive animation frames that share the
// time-invariant photons of a block assemble them
// (render/animation_progressive.cpp). Called with the pass index.
using PassMapSource = std::function<PhotonMaps(int pass, const Progress& progress)>;

// Runs one pass (index state.passesDone) and adds it into `state`; pixel p
// takes counts[p] eye samples (render/sample_allocation.h), or opt.spp when
// `counts` is empty; its maps from `source` when it is set.
void runProgressivePass(const Scene& scene, const RenderOptions& opt, ProgressiveState& state,
                        const Progress& progress, RenderStats& stats, const std::vector<uint32_t>& counts = {},
                        const PassMapSource& source = {});

// renderProgressive's parts, for a caller that runs the passes itself
// (progressive animation frames, render/animation_progressive.cpp): the
// checks, the memory budget of one pass, the state prepared (a new one's
// layers and settings, a resumed one checked), and the per-pixel sample
// counts and the time limit (opt.timeLimitSeconds, or the default when
// neither it nor opt.passes is set); then the film and figures of a state.
struct ProgressiveStart {
  std::vector<uint32_t> counts;
  double limit = 0;
};
ProgressiveStart startProgressive(const Scene& scene, const RenderOptions& opt, ProgressiveState& state,
                                  const Progress& progress, RenderStats& stats, dist::Comm& comm = dist::local());
Film finishProgressive(const Scene& scene, const ProgressiveState& state, RenderStats& stats, double seconds);

// The pass loop: continues `state` (empty: from pass 0) until opt.passes
// passes are done in all, or this run has taken opt.timeLimitSeconds (after
// the pass that reaches it), or core/signals reports a stop request (after
// the current pass). Without either limit, kDefaultProgressiveSeconds.
// Throws tdpm::Error for a method other than time, accumulation, standard,
// or a state whose layers do not match the image size.
//
// Distributed (comm.size() = N > 1, every rank calls it alike; rank 0 holds
// the state, the others an empty one): rounds of N passes, pass first + r on
// rank r alone (its own photons, every pixel), the pixel means sent to rank
// 0, which adds them in pass order: bit-identical to one process with the
// same passes. The time limit and a signal are checked after each round (so
// the job may run one round past the limit). Only rank 0 returns the image
// (the others an empty Film). docs/distributed.md.
Film renderProgressive(const Scene& scene, const RenderOptions& opt, ProgressiveState& state,
                       const Progress& progress, RenderStats& stats, dist::Comm& comm = dist::local());

// The image of a state: sum / passes, spp, and the variance of the mean of
// the pass means.
Film filmFromState(const ProgressiveState& state, int width, int height);

}  // namespace tdpm
