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

// The photon maps the options will really trace (a caustic map needs a
// specular surface, any map needs a light; accumulation traces 1/N per
// frame, one frame's maps at a time).
struct PhotonCounts {
  size_t caustic = 0, global = 0;
  bool spaceTime = false;
};

PhotonCounts photonCounts(const Scene& scene, const RenderOptions& opt) {
  PhotonCounts p;
  const RenderMethodTraits& method = renderMethodTraits(opt.method);
  if (!method.photonMaps || scene.lights.empty()) return p;
  p.caustic = photon::sceneHasSpecular(scene) ? opt.causticPhotons : 0;
  p.global = wantsGlobalMap(opt) ? opt.globalPhotons : 0;
  if (method.inBetweenFrames) {
    size_t frames = size_t(scene.hasMotion ? std::max(1, opt.frames) : 1);
    p.caustic = (p.caustic + frames - 1) / frames;
    p.global = (p.global + frames - 1) / frames;
  } else {
    p.spaceTime = opt.spaceTime4D && method.spreadsPhotonsInTime && scene.hasMotion;
  }
  return p;
}

}  // namespace

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
  e.photons = photonMemoryBytes(p.caustic, p.global, p.spaceTime, opt.maxDepth);
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
    checkPhotonMemory(p.caustic, p.global, p.spaceTime, opt.maxDepth, available, opt.causticPhotonsSource,
                      opt.globalPhotonsSource);
  const std::string image = opt.resolutionSource + " (" + std::to_string(scene.camera.width()) + "x" +
                            std::to_string(scene.camera.height()) + " = " + std::to_string(e.pixels) + " pixels)";
  const std::string imageNeeds =
      formatBytes(imageAlone) + " for the image (" + std::to_string((e.films + e.sampler) / std::max<uint64_t>(1, e.pixels)) +
      " bytes per pixel while rendering, " + std::to_string(kWriteBytesPerPixel) + " while writing the EXR and PNG)";
  const std::string limits = ", but only " + formatBytes(usable) + " of memory is available (MemAvailable " +
                             formatBytes(available) + " less a margin of " + formatBytes(margin) + ")";
  if (imageAlone > usable)
    throw Error(image + " needs about " + imageNeeds + limits + "; lower the resolution");
  throw Error(image + " and the photon maps (" + opt.causticPhotonsSource + ": " + std::to_string(p.caustic) +
              " caustic, " + opt.globalPhotonsSource + ": " + std::to_string(p.global) +
              " global) together need about " + formatBytes(e.peak()) + ": " + imageNeeds + " and " +
              formatBytes(e.photons) + " for the photons" + limits + "; lower the resolution or the photon counts");
}

}  // namespace tdpm
