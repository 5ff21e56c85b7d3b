// render/memory_budget.h — the one memory pre-flight of a render: the
// image (films while rendering, the EXR and PNG buffers while writing), the
// per-thread sample buffers and the photon maps (photonMemoryBytes, per
// kind), summed and checked against MemAvailable before any
// work, so an impossible --resolution or photon count is a located error
// and not an OOM kill half an hour in.
#pragma once
#include <cstdint>
#include <string>

#include "render/renderer.h"

namespace tdpm {

// Bytes per pixel, as render/ and the write path hold them (measured with
// `tdpm render --stats`, see docs/output-safety.md):
// a Film: colour (12) + samples taken (4) + variance of the mean (12).
constexpr uint64_t kFilmBytesPerPixel = 2 * 12 + 4;
// Writing: the film moved into the EXR (28) + the three split variance
// layers while the interleaved variance still exists (12); the 8-bit
// preview (3) comes after that variance is freed (render/film_output.h).
constexpr uint64_t kWriteBytesPerPixel = kFilmBytesPerPixel + 12;
// Per camera sample of a batch, per thread: the sample (12) + its strata (12).
constexpr uint64_t kSampleBytes = 24;

// ---- the photon maps' model ----
// Peak bytes the photon passes hold for maps of `stored` photons per kind
// (each map is traced while the ones before it in kind order are held):
// 20 bytes per stored photon, a second 3D-ordered copy for the 4D search,
// and the transients: the per-batch buffers while tracing (up to 2x their
// size from vector growth, alive until they are concatenated) or the
// kd-tree builder's keys and permutation, plus the pilot run.
uint64_t photonMemoryBytes(const PerMap<size_t>& stored, bool spaceTime4D, int maxDepth);
// Memory kept back from MemAvailable for everything that is not photons
// (scene, film, threads, other processes' growth).
uint64_t memoryMarginBytes(uint64_t available);
// Throws tdpm::Error naming the source of each count (the flag or scene key
// that set it; the one whose map alone does not fit, else all), the bytes
// needed and the bytes available when photonMemoryBytes(...) > available -
// margin. available == 0 means unknown (no /proc): no check.
void checkPhotonMemory(const PerMap<size_t>& stored, bool spaceTime4D, int maxDepth, uint64_t available,
                       const PerMap<std::string>& sources);

// An animation block's kept path states (render/animation.cpp, section 8 of
// docs/animation.md): at most one per block path of each kind, `paths` in
// all, `bytesPerState` each, on top of `held` bytes the block already holds.
// Throws tdpm::Error (naming --window and --no-continue-paths) when that
// worst case exceeds `available` less memoryMarginBytes; available == 0
// means unknown: no check.
void checkKeptStatesMemory(uint64_t paths, uint64_t bytesPerState, uint64_t held, uint64_t available, int window);

// Progressive frames sharing a block's photons (render/animation_progressive.cpp)
// hold the states of the block's `frames` frames at once, `bytesPerFrame`
// each (their float layers). Throws tdpm::Error naming --window when they
// exceed `available` less memoryMarginBytes; available == 0: no check.
void checkBlockStatesMemory(uint64_t frames, uint64_t bytesPerFrame, uint64_t available, int window);

struct MemoryEstimate {
  uint64_t pixels = 0;
  uint64_t films = 0;    // the films alive while rendering (accumulation: 3)
  uint64_t sampler = 0;  // the adaptive loop's per-pixel state (kSamplerBytesPerPixel)
  uint64_t samples = 0;  // per-thread batch buffers
  uint64_t photons = 0;  // photonMemoryBytes of the maps traced (one frame's for accumulation)
  uint64_t write = 0;    // the EXR and PNG buffers while writing
  // The most held at once: rendering (films + sampler + samples + photons) or writing.
  uint64_t peak() const;
};

// What rendering `scene` with `opt` on `threads` threads holds at its peak.
MemoryEstimate estimateRenderMemory(const Scene& scene, const RenderOptions& opt, int threads);

// Throws tdpm::Error when estimateRenderMemory(...).peak() exceeds
// `available` less memoryMarginBytes: naming opt.resolutionSource when the
// image alone does not fit, else the photon counts' sources (as
// checkPhotonMemory does), else both, with bytes needed and available.
// available == 0 means unknown (no /proc): no check.
void checkMemoryBudget(const Scene& scene, const RenderOptions& opt, int threads, uint64_t available);

}  // namespace tdpm
