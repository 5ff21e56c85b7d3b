// render/memory_budget.cpp — the render's peak memory, from the scene and
// the options, and the pre-flight check against available memory.
#include "render/memory_budget.h"

#include <algorithm>
#include <cstdio>

#include "core/error.h"
#include "photon/tracer.h"
#include "render/photon_map.h"

namespace tdpm {

namespace {

std::string formatBytes(uint64_t b) {
  char buf[64];
  if (b >= (uint64_t(1) << 30)) std::snprintf(buf, sizeof buf, "%.2f GiB", double(b) / double(uint64_t(1) << 30));
  else std::snprintf(buf, sizeof buf, "%.1f MiB", double(b) / double(uint64_t(1) << 20));
  return std::to_string(b) + " bytes (" + buf + ")";
}

// Bytes per stored photon, as photon/ holds them (docs/photon-map.md):
constexpr uint64_t kStoreBytes = 20;        // the store; the kd-tree adds nothing
// Tracing appends chunks of batches to a store reserved for the expected
// count (photon/tracer.cpp), then shrinks it to fit: one copy of the store.
constexpr uint64_t kShrinkBytes = 20;
// A chunk's per-batch buffers: up to 2x the photons they hold from vector
// growth, for at most kChunkPaths paths (kBatchesPerChunk x kPathsPerBatch).
constexpr uint64_t kChunkBytes = 2 * 20;
constexpr uint64_t kChunkPaths = 256 * 1024;
constexpr uint64_t kBuild3Bytes = 16 + 5;   // kd-tree builder: 3D keys + index, then permutation + axis
constexpr uint64_t kBuild4Bytes = 20 + 5;   // 4D keys + index, permutation + axis
constexpr uint64_t kPilotPaths = 16 * 1024; // photon/tracer.cpp: 16 pilot batches of 1024 paths
// The volume map (photon/volume_beam_map.h): the store and its tree (20),
// plus radius, window and subtree-bound codes (3): bytesPerPhoton's 23.
// Never 4D. Its build adds one float radius a photon to the 3D builder's.
constexpr uint64_t kBeamCodeBytes = 3;
constexpr uint64_t kBeamBuildBytes = 4;

// The photon maps the options will really trace (a caustic map needs a
// specular surface, any map needs a light; accumulation traces 1/N per
// frame, one frame's maps at a time).
struct PhotonCounts {
  PerMap<size_t> stored;
  bool spaceTime = false;
};

PhotonCounts photonCounts(const Scene& scene, const RenderOptions& opt) {
  PhotonCounts p;
  const RenderMethodTraits& method = renderMethodTraits(opt.method);
  if (!method.photonMaps || scene.lights.empty()) return p;
  p.stored = photonsWanted(opt);
  if (!photon::sceneHasSpecular(scene)) p.stored[MapKind::Caustic] = 0;
  if (!scene.hasMedia()) p.stored[MapKind::Volume] = 0;
  if (method.inBetweenFrames) {
    size_t frames = size_t(scene.hasMotion ? std::max(1, opt.frames) : 1);
    for (MapKind k : kAllMapKinds) p.stored[k] = (p.stored[k] + frames - 1) / frames;
  } else {
    p.spaceTime = opt.spaceTime4D && method.spreadsPhotonsInTime && scene.hasMotion;
  }
  return p;
}

PerMap<std::string> photonSources(const RenderOptions& opt) {
  PerMap<std::string> s;
  for (MapKind k : kAllMapKinds) s[k] = opt.*mapKindInfo(k).photonsSource;
  return s;
}

}  // namespace

uint64_t photonMemoryBytes(const PerMap<size_t>& stored, bool spaceTime4D, int maxDepth) {
  // One map: what it keeps, and the most it holds at once while it is made.
  auto kept = [&](MapKind k, uint64_t n) {
    if (k == MapKind::Volume) return n * (kStoreBytes + kBeamCodeBytes);
    return n * kStoreBytes * (spaceTime4D ? 2 : 1);
  };
  auto peak = [&](MapKind k, uint64_t n, uint64_t storedPerPilotPath) {
    if (n == 0) return uint64_t(0);
    uint64_t chunk = std::min<uint64_t>(n, kChunkPaths * storedPerPilotPath) * kChunkBytes;
    uint64_t tracing = n * (kStoreBytes + kShrinkBytes) + chunk;
    // 3D: store + builder. 4D: the 3D copy is kept while the 4D tree is built.
    uint64_t building = k == MapKind::Volume ? n * (kStoreBytes + kBuild3Bytes + kBeamCodeBytes + kBeamBuildBytes)
                        : spaceTime4D        ? n * (2 * kStoreBytes + kBuild4Bytes)
                                             : n * (kStoreBytes + kBuild3Bytes);
    uint64_t pilot = kPilotPaths * storedPerPilotPath * (kStoreBytes + kChunkBytes);
    return std::max({tracing, building, pilot});
  };
  // The maps are traced in kind order, each while the ones before are held.
  // A caustic path stores at most one photon; a global path one per bounce.
  uint64_t held = 0, most = 0;
  for (MapKind k : kAllMapKinds) {
    const uint64_t perPath = mapKindInfo(k).storesEveryBounce ? uint64_t(std::max(1, maxDepth)) + 1 : 1;
    most = std::max(most, held + peak(k, stored[k], perPath));
    held += kept(k, stored[k]);
  }
  return most;
}

uint64_t memoryMarginBytes(uint64_t available) { return (uint64_t(256) << 20) + available / 16; }

void checkKeptStatesMemory(uint64_t paths, uint64_t bytesPerState, uint64_t held, uint64_t available, int window) {
  if (available == 0) return;
  const uint64_t margin = memoryMarginBytes(available);
  const uint64_t usable = available > margin ? available - margin : 0;
  const double needed = double(paths) * double(bytesPerState) + double(held);
  if (needed <= double(usable)) return;
  throw Error("the animation's block of " + std::to_string(window) + " frames traces " + std::to_string(paths) +
              " photon paths, and continuing the paths that meet motion may keep a state of each (" +
              formatBytes(uint64_t(needed)) + " with what the block holds), but only " + formatBytes(usable) +
              " of memory is available (MemAvailable " + formatBytes(available) + " less a margin of " +
              formatBytes(margin) + "); lower --window or the photon counts, or trace every frame from the light "
              "with --no-continue-paths");
}

void checkBlockStatesMemory(uint64_t frames, uint64_t bytesPerFrame, uint64_t available, int window) {
  if (available == 0) return;
  const uint64_t margin = memoryMarginBytes(available);
  const uint64_t usable = available > margin ? available - margin : 0;
  const double needed = double(frames) * double(bytesPerFrame);
  if (needed <= double(usable)) return;
  throw Error("--progressive frames sharing their block's photons hold the states of " + std::to_string(frames) +
              " frames at once (--window " + std::to_string(window) + ", " + formatBytes(bytesPerFrame) +
              " each: " + formatBytes(uint64_t(needed)) + "), but only " + formatBytes(usable) +
              " of memory is available (MemAvailable " + formatBytes(available) + " less a margin of " +
              formatBytes(margin) + "); lower --window or the resolution, or render each frame alone with "
              "--shared-photons 0");
}

void checkPhotonMemory(const PerMap<size_t>& stored, bool spaceTime4D, int maxDepth, uint64_t available,
                       const PerMap<std::string>& sources) {
  if (available == 0) return;  // unknown: better to try than to refuse
  uint64_t margin = memoryMarginBytes(available);
  uint64_t usable = available > margin ? available - margin : 0;
  uint64_t needed = photonMemoryBytes(stored, spaceTime4D, maxDepth);
  if (needed <= usable) return;
  // Blame the count that alone does not fit, else all together.
  std::string what, names, counts;
  for (MapKind k : kAllMapKinds) {
    if (mapKindInfo(k).onlyWhenAsked && stored[k] == 0) continue;  // no volume map: not named
    PerMap<size_t> alone;
    alone[k] = stored[k];
    const std::string count = std::to_string(stored[k]) + " " + mapKindName(k);
    if (what.empty() && photonMemoryBytes(alone, spaceTime4D, maxDepth) > usable)
      what = sources[k] + " asks for " + count + " photons";
    names += (names.empty() ? "" : " and ") + sources[k];
    counts += (counts.empty() ? "" : " and ") + count;
  }
  if (what.empty()) what = names + " ask for " + counts + " photons";
  throw Error(what + (spaceTime4D ? " with --search 4d" : "") + ", which need about " + formatBytes(needed) +
              " while tracing and building the kd-trees, but only " + formatBytes(usable) +
              " of memory is available (MemAvailable " + formatBytes(available) + " less a margin of " +
              formatBytes(margin) + "); lower the photon counts");
}


uint64_t MemoryEstimate::peak() const { return std::max(films + sampler + samples + photons, write); }

MemoryEstimate estimateRenderMemory(const Scene& scene, const RenderOptions& opt, int threads) {
  MemoryEstimate e;
  e.pixels = uint64_t(std::max(0, scene.camera.width())) * uint64_t(std::max(0, scene.camera.height()));
  // accumulation keeps the result, the running sum and the current frame.
  const uint64_t films = renderMethodTraits(opt.method).inBetweenFrames && scene.hasMotion && opt.frames > 1 ? 3 : 1;
  e.films = films * kFilmBytesPerPixel * e.pixels;
  e.sampler = kSamplerBytesPerPixel * e.pixels;  // one film is sampled at a time
  e.samples = uint64_t(std::max(1, threads)) * uint64_t(std::max(1, opt.spp)) * kSampleBytes;
  PhotonCounts p = photonCounts(scene, opt);
  e.photons = photonMemoryBytes(p.stored, p.spaceTime, opt.maxDepth);
  e.write = kWriteBytesPerPixel * e.pixels;
  return e;
}

void checkMemoryBudget(const Scene& scene, const RenderOptions& opt, int threads, uint64_t available) {
  if (available == 0) return;  // unknown: better to try than to refuse
  const MemoryEstimate e = estimateRenderMemory(scene, opt, threads);
  const uint64_t margin = memoryMarginBytes(available);
  const uint64_t usable = available > margin ? available - margin : 0;
  if (e.peak() <= usable) return;
  const PhotonCounts p = photonCounts(scene, opt);
  const uint64_t imageAlone = std::max(e.films + e.sampler + e.samples, e.write);
  // The photons alone do not fit: the photon budget's own message.
  if (imageAlone <= usable && e.photons > usable)
    checkPhotonMemory(p.stored, p.spaceTime, opt.maxDepth, available, photonSources(opt));
  const std::string image = opt.resolutionSource + " (" + std::to_string(scene.camera.width()) + "x" +
                            std::to_string(scene.camera.height()) + " = " + std::to_string(e.pixels) + " pixels)";
  const std::string imageNeeds =
      formatBytes(imageAlone) + " for the image (" + std::to_string((e.films + e.sampler) / std::max<uint64_t>(1, e.pixels)) +
      " bytes per pixel while rendering, " + std::to_string(kWriteBytesPerPixel) + " while writing the EXR and PNG)";
  const std::string limits = ", but only " + formatBytes(usable) + " of memory is available (MemAvailable " +
                             formatBytes(available) + " less a margin of " + formatBytes(margin) + ")";
  if (imageAlone > usable)
    throw Error(image + " needs about " + imageNeeds + limits + "; lower the resolution");
  std::string maps;
  for (MapKind k : kAllMapKinds)
    if (mapKindInUse(opt, k))
    maps += (maps.empty() ? "" : ", ") + opt.*mapKindInfo(k).photonsSource + ": " + std::to_string(p.stored[k]) + " " +
            mapKindName(k);
  throw Error(image + " and the photon maps (" + maps + ") together need about " + formatBytes(e.peak()) + ": " + imageNeeds + " and " +
              formatBytes(e.photons) + " for the photons" + limits + "; lower the resolution or the photon counts");
}

}  // namespace tdpm
