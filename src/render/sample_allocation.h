// render/sample_allocation.h — how many eye samples each pixel takes per
// progressive pass (docs/photon-map.md section 7, "Eye samples where the
// eye paths are noisy").
//
// Before pass 0 an eye-only pilot (eye paths with their path-traced parts:
// emission seen directly or through mirrors and glass, and direct light at
// the first non-specular hit; no photon map, no final gather) takes
// kPilotSamples samples per pixel from a sequence of its own (a seed hashed
// from --seed), measures each pixel's relative standard deviation per
// sample, and then discards them. Every pass gives pixel p the same m_p >=
// spp samples, m_p proportional to that deviation (the allocation that
// minimises the sum of relative variances for a sample budget), at most
// cap x spp, with at most `budget` x spp x pixels samples above spp in all.
// The map is a function of (scene, options, seed) only, so it is the same in
// every run, on every rank and after --resume; and it is independent of the
// samples that are averaged, so each pass value stays an unbiased mean.
#pragma once
#include <cstdint>
#include <vector>

#include "core/progress.h"
#include "distributed/comm.h"
#include "render/render_options.h"
#include "scene/scene.h"

namespace tdpm {

// Samples per pixel of the pilot (discarded).
constexpr int kPilotSamples = 32;

// The pilot's per-pixel noise: relative standard deviation of one eye
// sample's luminance (3x3 neighbourhood's mean variance over its mean, with
// a floor of kNoiseFloorFraction x the image's mean luminance, dilated by
// kDilation), row-major.
// Distributed: each rank traces its tiles, the values are shared, every
// rank returns the whole image's (bit-identical to one process).
std::vector<float> pilotNoise(const Scene& scene, const RenderOptions& opt, const Progress& progress,
                              dist::Comm& comm = dist::local());
constexpr double kNoiseFloorFraction = 0.5;
// ... and the largest such value within this many pixels (a square): a
// highlight that the pilot samples meet in one pixel of a streak stands for
// the streak's pixels that they missed.
constexpr int kDilation = 3;

// Samples per pass of each pixel from `noise`: m_p = clamp(ceil(c noise_p),
// spp, cap spp), with the largest c (bisection, deterministic) whose extra
// samples sum(m_p - spp) stay within budget x spp x pixels. budget <= 0 or
// cap <= 1: spp everywhere.
std::vector<uint32_t> allocatePassSamples(const std::vector<float>& noise, int spp, int cap, double budget);

// The map of a progressive render: empty when opt.passExtraSamples <= 0
// (every pixel takes opt.spp, the loop's old path), else
// allocatePassSamples(pilotNoise(...)).
std::vector<uint32_t> passSampleCounts(const Scene& scene, const RenderOptions& opt, const Progress& progress,
                                       dist::Comm& comm = dist::local());

}  // namespace tdpm
