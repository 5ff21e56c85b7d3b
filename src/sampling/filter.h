// sampling/filter.h — the pixel reconstruction filter, applied by filter
// importance sampling: a camera sample's offset from the pixel centre is
// drawn from the filter's own distribution, so every sample lands in one
// pixel with weight exactly 1 and a pixel's value stays the plain mean of
// its samples. That keeps the per-pixel determinism (any thread count),
// the adaptive half-buffers and the variance layer as they are.
//
// Kinds (--filter, scene key render.filter; radius in pixels by
// --filter-radius / render.filter_radius):
//   box       uniform over [-r, r]^2 around the pixel centre; r = 0.5 (the
//             default) is the pixel itself and gives the samples of the
//             unfiltered sampler bit for bit.
//   gaussian  pbrt-v4's GaussianFilter: per axis g(x) - g(r), where
//             g(x) = exp(-x^2 / (2 sigma^2)), sigma = 0.5 px, default
//             r = 1.5 px, clamped at 0; separable. It is tabulated in
//             kFilterBins bins per axis with each bin's exact integral
//             (erf), and sampled exactly from that step function by
//             inverting its piecewise-linear CDF. The step function *is*
//             the filter we apply (it differs from the smooth one by less
//             than 0.6% of its peak at 256 bins), so no f/pdf weight is
//             needed: pbrt-v4 tabulates too, but at 32 bins per pixel of
//             radius, and weights each sample by f/pdf.
// The inverse CDF is monotone, so a stratified u (Sobol, Latin hypercube)
// stays stratified in the filter's measure.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "math/vec.h"

namespace tdpm {

enum class FilterKind { Box, Gaussian };
const char* filterName(FilterKind k);
// false when `name` is neither "box" nor "gaussian".
bool parseFilterKind(const std::string& name, FilterKind& out);
// Radius in pixels when none is given: box 0.5 (one pixel), gaussian 1.5.
float defaultFilterRadius(FilterKind k);
constexpr float kGaussianFilterSigma = 0.5f;  // pixels, pbrt-v4's default

class PixelFilter {
 public:
  static constexpr int kFilterBins = 256;  // per axis, over [-r, r]

  PixelFilter() : PixelFilter(FilterKind::Box, 0.5f) {}
  // radius > 0 (limits::kFilterRadius); the caller validates.
  PixelFilter(FilterKind kind, float radius);

  FilterKind kind() const { return kind_; }
  float radius() const { return radius_; }

  // u in [0,1)^2 -> the sample's position relative to the pixel's corner
  // (pixel x + result.x), i.e. 0.5 + an offset drawn from the filter.
  // (Box: (0.5 - r) + 2r u, which for r = 0.5 is u itself, bit for bit.)
  Vec2f sample(Vec2f u) const {
    if (kind_ == FilterKind::Box) return {(0.5f - radius_) + 2.0f * radius_ * u.x, (0.5f - radius_) + 2.0f * radius_ * u.y};
    return {0.5f + sample1D(u.x), 0.5f + sample1D(u.y)};
  }
  // One axis: u in [0,1) -> offset from the pixel centre, in [-r, r).
  float sample1D(float u) const;
  // Normalised 1D density of the offsets sample1D draws (integrates to 1).
  float pdf1D(float x) const;

 private:
  FilterKind kind_;
  float radius_;
  std::vector<float> cdf_;  // gaussian: kFilterBins + 1 values, 0 .. 1
  // guide_[j]: the bin holding u = j / kFilterBins, so a lookup starts
  // there and steps a bin or two instead of a binary search.
  std::vector<uint16_t> guide_;
};

}  // namespace tdpm
