// render/animation.h — frame sequences from one photon timeline
// (docs/animation.md). The scene is built once over the whole timeline
// [0, frames / fps]; photons are traced once over the parts of it that some
// frame can use (its shutter, and the closed-shutter time its time kernel
// may reach), in segments on one grid of time bins, and each frame renders
// with renderFrame() (render/renderer.h) from a map assembled from the
// segments around it. Only a sliding window of frames' segments is held.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/progress.h"
#include "motion/shutter.h"
#include "render/film.h"
#include "render/progressive_state.h"
#include "render/renderer.h"
#include "scene/description.h"
#include "scene/scene.h"

namespace tdpm {

// The time grid every segment and frame map shares: bins of `binWidth`
// seconds, `binsPerFrame` to a frame period (so every shutter opens on a
// bin edge). Frame i's shutter is bins [i B, i B + S), its time map spans
// [i B - P, i B + S + P), with S + 2P <= 256 (one 8-bit photon time range).
struct TimeGrid {
  int64_t binsPerFrame = 256;  // B
  int64_t shutterBins = 128;   // S (the shutter, rounded to whole bins when B * angle / 360 is not whole)
  int64_t padBins = 0;         // P: how far the time kernel reaches beyond the shutter, plus one bin
  double binWidth = 1.0;       // seconds: 1 / (B fps)
  int64_t mapLo(int frame) const { return int64_t(frame) * binsPerFrame - padBins; }
  int64_t mapHi(int frame) const { return int64_t(frame) * binsPerFrame + shutterBins + padBins; }
};

// reach: the time kernel's largest distance, as a fraction of the shutter
// (capped at 1). Chooses the largest B that fits, preferring one that makes
// S whole.
TimeGrid makeTimeGrid(const scene::AnimationDesc& animation, double reach);

// Frame i's shutter in scene seconds: [i / fps, i / fps + (angle / 360) / fps].
Shutter frameShutter(const scene::AnimationDesc& animation, int frame);

struct AnimationOptions {
  int first = 0, last = 0;  // frames to render, inclusive
  int window = 4;           // frames whose photon segments are traced and held together
  // Photon segments seeded by their place on the timeline, so that frames'
  // photons are independent; default: by their place in the frame period,
  // so corresponding paths of every frame share random numbers and still
  // lighting does not flicker (docs/animation.md).
  bool independentFrames = false;
  // Time-invariant photons (docs/animation.md section 7): frames are taken
  // in blocks of `window` from frame 0 (frames [jK, (j+1)K), whatever range
  // a run renders); the photons whose path misses everything that moves
  // over a block's time are traced once for the block, with `sharedScale`
  // times the paths one frame's time map traces, and every frame of the
  // block uses them all. The frames' own segments keep only the photons
  // whose path meets motion, traced with `movingScale` times their paths.
  // sharedScale 0: no sharing (every frame traces all its photons).
  // Measured defaults (continuing the paths that meet motion, --window 4,
  // 8 seeds): docs/animation.md "Defaults and what they buy".
  double sharedScale = 0.5;
  double movingScale = 0.5;
  // With sharing: the frames' photons whose path meets motion are continued
  // from the block pass's paths at their last time-invariant vertex
  // instead of traced from the light (docs/animation.md section 8). Scenes
  // with media always trace from the light. Measured default:
  // docs/animation.md section 8.
  bool continuePaths = true;
  // --progressive with --resume (docs/animation.md "Resuming progressive
  // frames"): the state frame `frame` starts from, given its options (with
  // its shutter as frameOpen/frameClose); empty function: a fresh state.
  // A frame whose state already has opt.passes passes is skipped (no pass,
  // no sink call). keepState receives each rendered frame's final state
  // just before the sink, so the caller can write it with the frame.
  std::function<ProgressiveState(int frame, const RenderOptions& frameOptions)> startState;
  std::function<void(int frame, ProgressiveState&& state)> keepState;
};

struct AnimationStats {
  double photonSeconds = 0;                   // tracing, and building frame maps
  // Its parts (--stats): the blocks' pilots and shared sets, the frames'
  // own segments, and the frames' maps (copies and kd-trees).
  double sharedSeconds = 0, segmentSeconds = 0, mapSeconds = 0;
  PerMap<MapStats> maps;                      // stored and emitted per map kind
  uint64_t segmentsTraced = 0;
  uint64_t sharedSets = 0;                    // blocks whose time-invariant photons were traced
  size_t sharedPhotons = 0;                   // time-invariant photons stored, all blocks and kinds
  // The frames' own segments: paths emitted and photons stored, and those
  // of the pads (segments outside every shutter: the time kernel's reach).
  uint64_t segmentPaths = 0, padPaths = 0;
  size_t segmentPhotons = 0, padPhotons = 0;
  // Continuation: the block passes' kept path states (the most held at
  // once, all kinds) and the frames' continued paths (of segmentPaths).
  size_t peakKeptStates = 0;
  uint64_t continuedPaths = 0;
  uint64_t framesSkipped = 0;                 // --progressive --resume: frames already finished
  uint64_t passesDone = 0;                    // --progressive: passes of all frames this run (no segments are traced)
  size_t peakHeldPhotons = 0;                 // segments + the frame's maps, at most
  std::vector<std::string> warnings;
};

// Called after each frame with its film and statistics (photon figures of
// the frame: its maps' sizes), in frame order; the caller writes the files.
using FrameSink = std::function<void(int frame, Film&& film, const RenderStats& stats)>;

// --progressive frames sharing each pass's time-invariant photons over
// blocks of animationOptions.window frames (--shared-photons > 0, a scene
// without media): render/animation_progressive.h.
bool progressiveFramesShare(const Scene& scene, const RenderOptions& options, const AnimationOptions& animationOptions);

// --progressive: frame `frame`'s options, its shutter as frameOpen /
// frameClose and, when its passes share the time-invariant photons of its
// block, what they depend on as frameSharing (both in the fingerprint).
RenderOptions progressiveFrameOptions(const Scene& scene, const scene::AnimationDesc& animation,
                                      const RenderOptions& options, const AnimationOptions& animationOptions,
                                      int frame);

// Renders options.first..options.last. Methods: time, standard, pathtrace
// (others are refused with an Error). `--photons` counts are per frame's
// shutter time. Reports progress.at(WorkPosition{"frame", ...}).
// options.progressive: each frame is a progressive render (time, standard;
// --passes / --time-limit per frame), its passes' photons and camera samples
// in the frame's shutter; no segments; with sharing the frames of a block
// of `window` share each pass's time-invariant photons
// (render/animation_progressive.h).
AnimationStats renderAnimation(const Scene& scene, const scene::AnimationDesc& animation, const RenderOptions& options,
                               const AnimationOptions& animationOptions, const Progress& progress,
                               const FrameSink& sink);

}  // namespace tdpm
