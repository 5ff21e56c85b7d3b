// sampling/filter.cpp — filter names and the tabulated Gaussian's
// inverse-CDF sampling (sampling/filter.h).
#include "sampling/filter.h"

#include <algorithm>
#include <cmath>

namespace tdpm {

const char* filterName(FilterKind k) { return k == FilterKind::Box ? "box" : "gaussian"; }

bool parseFilterKind(const std::string& name, FilterKind& out) {
  if (name == "box") out = FilterKind::Box;
  else if (name == "gaussian") out = FilterKind::Gaussian;
  else return false;
  return true;
}

float defaultFilterRadius(FilterKind k) { return k == FilterKind::Box ? 0.5f : 1.5f; }

namespace {
// Integral over [a, b] of exp(-x^2 / (2 s^2)) - exp(-r^2 / (2 s^2)), |a|, |b| <= r.
double truncatedGaussianIntegral(double a, double b, double s, double r) {
  const double k = 1.0 / (s * std::sqrt(2.0));
  double g = 0.5 * std::sqrt(2.0 * M_PI) * s * (std::erf(b * k) - std::erf(a * k));
  return g - (b - a) * std::exp(-r * r / (2.0 * s * s));
}
}  // namespace

PixelFilter::PixelFilter(FilterKind kind, float radius) : kind_(kind), radius_(radius) {
  if (kind_ != FilterKind::Gaussian) return;
  cdf_.resize(kFilterBins + 1);
  const double r = radius_, w = 2.0 * r / kFilterBins;
  double sum = 0;
  cdf_[0] = 0;
  std::vector<double> acc(kFilterBins + 1, 0.0);
  for (int i = 0; i < kFilterBins; ++i) {
    double a = -r + i * w, b = a + w;
    sum += std::max(0.0, truncatedGaussianIntegral(a, b, kGaussianFilterSigma, r));
    acc[size_t(i) + 1] = sum;
  }
  for (int i = 1; i <= kFilterBins; ++i) cdf_[size_t(i)] = float(acc[size_t(i)] / sum);
  cdf_[kFilterBins] = 1.0f;
  guide_.resize(kFilterBins);
  size_t i = 0;
  for (int j = 0; j < kFilterBins; ++j) {
    float u = float(j) / float(kFilterBins);
    while (i + 1 < size_t(kFilterBins) && cdf_[i + 1] <= u) ++i;
    guide_[size_t(j)] = uint16_t(i);
  }
}

float PixelFilter::sample1D(float u) const {
  if (kind_ == FilterKind::Box) return (2.0f * u - 1.0f) * radius_;
  // The bin i with cdf[i] <= u < cdf[i+1], then linear inside it.
  size_t i = guide_[std::min(size_t(u * float(kFilterBins)), size_t(kFilterBins - 1))];
  while (i + 1 < size_t(kFilterBins) && cdf_[i + 1] <= u) ++i;
  float lo = cdf_[i], hi = cdf_[i + 1];
  float t = hi > lo ? (u - lo) / (hi - lo) : 0.5f;
  float w = 2.0f * radius_ / float(kFilterBins);
  float x = -radius_ + (float(i) + std::min(t, 0x1.fffffep-1f)) * w;
  return std::min(x, std::nextafter(radius_, 0.0f));
}

float PixelFilter::pdf1D(float x) const {
  if (!(std::fabs(x) < radius_)) return 0.0f;
  if (kind_ == FilterKind::Box) return 0.5f / radius_;
  float w = 2.0f * radius_ / float(kFilterBins);
  int i = std::min(kFilterBins - 1, int((x + radius_) / w));
  return (cdf_[size_t(i) + 1] - cdf_[size_t(i)]) / w;
}

}  // namespace tdpm
