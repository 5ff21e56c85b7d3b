// image/metrics.h — error metrics between a test image and a reference
// image (what `tdpm compare` prints and the reproduction measures).
// Owns: PixelRect, ChannelMetrics, ImageMetrics, compareImages, cropInside,
// SaltMetrics / countSalt (isolated bright outliers, issue 24).
// Pure functions over ImageRgb: no files, no printing.
//
// Definitions (v = test value, r = reference value, one pixel channel; every
// mean is over the pixels of the region, per channel; "overall" combines the
// three channels as stated per field):
//   MSE      mean (v - r)^2                         overall: mean of the channels
//   RMSE     sqrt(MSE)                               overall: sqrt(overall MSE)
//   relMSE   mean (v - r)^2 / (r + 0.01)^2           overall: mean of the channels
//   MAE      mean |v - r|                            overall: mean of the channels
//   maxAbs   max |v - r|                             overall: max of the channels
//   mean     mean v (test), mean r (reference)       overall: mean of the channels
// relMSE is pbrt-v4's "MRSE" exactly (see metrics.cpp for the source): the
// number `imgtool diff --metric MRSE` prints for the same two images.
#pragma once
#include <cstddef>
#include <optional>

#include "image/image.h"

namespace tdpm::image {

// A pixel rectangle: columns [x, x + w), rows [y, y + h); (0, 0) is the top
// left pixel, like ImageRgb.
struct PixelRect {
  int x = 0, y = 0, w = 0, h = 0;
};

// True if `r` has w, h >= 1 and lies entirely inside a width x height image.
bool cropInside(const PixelRect& r, int width, int height);

struct ChannelMetrics {
  double mse = 0, rmse = 0, relMse = 0, mae = 0, maxAbs = 0;
  double meanTest = 0, meanRef = 0;
};

struct ImageMetrics {
  ChannelMetrics channel[3];  // R, G, B
  ChannelMetrics overall;
  PixelRect region;         // the pixels measured
  size_t pixelCount = 0;    // region.w * region.h
  // Values (pixel channels) that were NaN or infinite. Like pbrt's imgtool,
  // they are counted as 0 so that one bad pixel does not turn every metric
  // into NaN; `tdpm compare` refuses such images unless --allow-nonfinite
  // (an Inf where the reference is 0 would otherwise score 0 error).
  size_t nonFiniteTest = 0, nonFiniteRef = 0;

  // (mean test - mean ref) / mean ref over all channels: how much energy the
  // test image gained (> 0) or lost (< 0). Empty if the reference is black.
  std::optional<double> relativeMeanDifference() const;
};

// NaN or infinite values (pixel channels) of `image` inside `region`, and
// where the first one is (row-major order); x = -1 when there is none.
struct NonFiniteValues {
  size_t count = 0;
  int x = -1, y = -1, channel = -1;
};
NonFiniteValues findNonFinite(const ImageRgb& image, const PixelRect& region);

// Compares `test` against `reference` over `region` (the whole image when
// empty). Sizes must match and the region must be inside (cropInside); the
// caller validates with file names in its messages, so a violation here is
// a bug (TDPM_ASSERT). Sums are in double, in row-major order, so the same
// images always give the same bits.
ImageMetrics compareImages(const ImageRgb& test, const ImageRgb& reference,
                           const std::optional<PixelRect>& region = std::nullopt);

// Salt: test pixels whose luminance (Rec. 709 Y) is above `factor` times
// both the reference's and the test's own median luminance over the 5x5
// window around the pixel (the window clipped at the image's borders; the
// neighbours may lie outside `region`, the pixels counted lie inside). A
// k-NN estimate's rare huge values show as such isolated pixels; a real
// bright feature is bright in the reference too, and a wide error is
// bright in the test's own median. Share = count / pixels of the region.
struct SaltMetrics {
  size_t count = 0;
  double share = 0;
};
constexpr double kSaltFactor = 3.0;
SaltMetrics countSalt(const ImageRgb& test, const ImageRgb& reference, const PixelRect& region,
                      double factor = kSaltFactor);

}  // namespace tdpm::image
