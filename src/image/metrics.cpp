// image/metrics.cpp — the error metrics of image/metrics.h.
//
// Relative MSE follows pbrt-v4 (Pharr, Jakob, Humphreys), so numbers here can
// be compared with numbers measured by pbrt's own tools:
//   * src/pbrt/util/image.cpp, Image::MRSE (github.com/mmp/pbrt-v4, commit
//     9e32a442255963c3d8222ef31a1f4f7fc8c65afb): per channel,
//       sum over pixels of Sqr(v - vref) / Sqr(vref + 0.01), skipping terms
//       that are infinite, divided by the pixel count;
//   * src/pbrt/cmd/imgtool.cpp, `diff`: clamps infinite pixel values to 0
//     first, then prints error.Average() (the mean over the channels) and
//     the two images' averages ("avg = test / ref").
// Note the denominator is (r + 0.01)^2, not r^2 + 0.01 (the form some
// denoising papers use): they differ a hundredfold on black reference pixels
// (1e-4 against 1e-2), so we keep pbrt's exactly, or our numbers would not be
// comparable with pbrt's.
#include "image/metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace tdpm::image {

namespace {

// pbrt-v4's epsilon in Image::MRSE: keeps dark reference pixels from
// dominating the relative error.
constexpr double kRelEpsilon = 0.01;

// NaN and +-inf count as 0 (see ImageMetrics::nonFinite*), like imgtool diff.
inline double finiteOrZero(float v, size_t& nonFinite) {
  if (std::isfinite(v)) return double(v);
  ++nonFinite;
  return 0.0;
}

}  // namespace

bool cropInside(const PixelRect& r, int width, int height) {
  // 64-bit sums: x + w must not overflow for hostile flag values.
  return r.w >= 1 && r.h >= 1 && r.x >= 0 && r.y >= 0 && int64_t(r.x) + r.w <= width &&
         int64_t(r.y) + r.h <= height;
}

NonFiniteValues findNonFinite(const ImageRgb& image, const PixelRect& region) {
  TDPM_ASSERT(cropInside(region, image.width, image.height), "findNonFinite: region outside the image");
  NonFiniteValues out;
  for (int y = region.y; y < region.y + region.h; ++y)
    for (int x = region.x; x < region.x + region.w; ++x)
      for (int c = 0; c < 3; ++c)
        if (!std::isfinite(image.at(x, y)[c]) && out.count++ == 0) out.x = x, out.y = y, out.channel = c;
  return out;
}

std::optional<double> ImageMetrics::relativeMeanDifference() const {
  if (overall.meanRef == 0.0) return std::nullopt;
  return (overall.meanTest - overall.meanRef) / overall.meanRef;
}

ImageMetrics compareImages(const ImageRgb& test, const ImageRgb& reference, const std::optional<PixelRect>& region) {
  TDPM_ASSERT(test.width == reference.width && test.height == reference.height, "compareImages: image sizes differ");
  TDPM_ASSERT(!test.empty(), "compareImages: empty image");
  ImageMetrics m;
  m.region = region.value_or(PixelRect{0, 0, test.width, test.height});
  TDPM_ASSERT(cropInside(m.region, test.width, test.height), "compareImages: region outside the image");
  m.pixelCount = size_t(m.region.w) * size_t(m.region.h);

  double sumSq[3] = {0, 0, 0}, sumRel[3] = {0, 0, 0}, sumAbs[3] = {0, 0, 0};
  double sumTest[3] = {0, 0, 0}, sumRef[3] = {0, 0, 0}, maxAbs[3] = {0, 0, 0};
  for (int y = m.region.y; y < m.region.y + m.region.h; ++y)
    for (int x = m.region.x; x < m.region.x + m.region.w; ++x) {
      const Rgb& t = test.at(x, y);
      const Rgb& r = reference.at(x, y);
      for (int c = 0; c < 3; ++c) {
        double v = finiteOrZero(t[c], m.nonFiniteTest);
        double vr = finiteOrZero(r[c], m.nonFiniteRef);
        double d = v - vr;
        sumSq[c] += d * d;
        double denom = (vr + kRelEpsilon) * (vr + kRelEpsilon);
        double rel = d * d / denom;
        if (std::isfinite(rel)) sumRel[c] += rel;  // pbrt skips infinite terms (vr == -0.01)
        sumAbs[c] += std::abs(d);
        maxAbs[c] = std::max(maxAbs[c], std::abs(d));
        sumTest[c] += v;
        sumRef[c] += vr;
      }
    }

  const double n = double(m.pixelCount);
  ChannelMetrics& o = m.overall;
  for (int c = 0; c < 3; ++c) {
    ChannelMetrics& ch = m.channel[c];
    ch.mse = sumSq[c] / n;
    ch.rmse = std::sqrt(ch.mse);
    ch.relMse = sumRel[c] / n;
    ch.mae = sumAbs[c] / n;
    ch.maxAbs = maxAbs[c];
    ch.meanTest = sumTest[c] / n;
    ch.meanRef = sumRef[c] / n;
    o.mse += ch.mse / 3;
    o.relMse += ch.relMse / 3;
    o.mae += ch.mae / 3;
    o.maxAbs = std::max(o.maxAbs, ch.maxAbs);
    o.meanTest += ch.meanTest / 3;
    o.meanRef += ch.meanRef / 3;
  }
  // Over all pixels and channels at once: sqrt of the mean squared error.
  o.rmse = std::sqrt(o.mse);
  return m;
}

namespace {
inline double luminance(const Rgb& c) {
  double v = 0.2126 * double(c.r) + 0.7152 * double(c.g) + 0.0722 * double(c.b);
  return std::isfinite(v) ? v : 0.0;
}
// Median luminance of the 5x5 window around (x, y), clipped to the image.
double median5x5(const ImageRgb& im, int x, int y) {
  double v[25];
  int n = 0;
  for (int yy = std::max(0, y - 2); yy <= std::min(im.height - 1, y + 2); ++yy)
    for (int xx = std::max(0, x - 2); xx <= std::min(im.width - 1, x + 2); ++xx) v[n++] = luminance(im.at(xx, yy));
  std::nth_element(v, v + n / 2, v + n);
  return v[n / 2];
}
}  // namespace

SaltMetrics countSalt(const ImageRgb& test, const ImageRgb& reference, const PixelRect& region, double factor) {
  TDPM_ASSERT(test.width == reference.width && test.height == reference.height, "countSalt: image sizes differ");
  TDPM_ASSERT(cropInside(region, test.width, test.height), "countSalt: region outside the image");
  SaltMetrics s;
  for (int y = region.y; y < region.y + region.h; ++y)
    for (int x = region.x; x < region.x + region.w; ++x) {
      double v = luminance(test.at(x, y));
      if (!(v > 0.0)) continue;
      if (v > factor * median5x5(reference, x, y) && v > factor * median5x5(test, x, y)) ++s.count;
    }
  s.share = double(s.count) / (double(region.w) * double(region.h));
  return s;
}

}  // namespace tdpm::image
