// estimate/volume_estimators.cpp — the non-template parts of the volume
// estimates: the k-NN and the two-pass time window of the point estimate,
// and the progressive kernel schedule.
#include "estimate/volume_estimators.h"

#include <algorithm>
#include <vector>

namespace tdpm::estimate {

TwoPassWindow twoPassTimeWindow(const uint8_t* bins, int nc, float u, float fraction, float maxDistBins) {
  TwoPassWindow out;
  const int keep = std::max(photon::keptCount(fraction, nc), kMinTimePhotons);
  if (keep >= nc) {
    // Too few to choose from: the known window, every photon in it counted.
    out.win = photon::binsWithinKey(u, std::isfinite(maxDistBins) ? 2.0f * maxDistBins : maxDistBins);
    if (out.win.empty()) return out;
    out.win.kept = 0;
    for (int i = 0; i < nc; ++i) out.win.kept += int(out.win.contains(bins[i]));
    return out;
  }
  out.win = photon::selectTimeWindow(bins, nc, u, keep, maxDistBins);
  if (out.win.empty() || out.win.kept < keep) return out;  // cut by maxTimeDistance: a known window
  // The keep-th photon closed the window: estimators.h's correction.
  float outer = std::max(photon::timeKey(out.win.lo, u), photon::timeKey(out.win.hi, u));
  photon::TimeWindow prev = photon::binsWithinKey(u, std::nextafter(outer, 0.0f));
  int prevKept = 0;
  if (!prev.empty())
    for (int i = 0; i < nc; ++i) prevKept += int(prev.contains(bins[i]));
  out.c = timeWindowCorrection(keep, out.win.hi - out.win.lo + 1, out.win.kept,
                               prev.empty() ? 0 : prev.hi - prev.lo + 1, prevKept);
  return out;
}

VolumeGatherer::VolumeGatherer(const photon::KdTree& tree, const VolumeOptions& options)
    : tree_(&tree), opt_(options), knn_(std::max(options.k, options.ks)) {}

int VolumeGatherer::nearest(Vec3f x, int k, float& r2) {
  const float maxR2 = opt_.maxRadius * opt_.maxRadius;
  const int found = tree_->knn(x, k, maxR2, knn_);
  if (found == 0) return -1;
  r2 = found == k ? knn_.radius2 : (std::isfinite(maxR2) ? maxR2 : knn_.maxFound2);
  r2 = std::max(r2, opt_.minRadius2);
  if (found == k) return 1;           // full heap: the root is the k-th, on the boundary
  if (std::isfinite(maxR2)) return 0;  // a known ball: all of it counted
  photon::moveFarthestFirst(knn_, found);  // the boundary photon, as Gatherer::boundaryFirst
  return 1;
}

double volumeKernelScale(int pass, double alpha, int dims) {
  double v = 1.0;
  for (int j = 1; j <= pass; ++j) v *= (double(j) + alpha) / double(j + 1);
  return std::pow(v, 1.0 / double(dims));
}

VolumeKernel pilotKernel(const photon::VolumeBeamMap& map) {
  const size_t n = map.size();
  if (n == 0) return {};
  const float binWidth = map.store().time().binWidth;
  std::vector<float> r(n), h(n);
  for (size_t i = 0; i < n; ++i) {
    r[i] = map.radius(i);
    uint8_t w = map.windowCode(i);
    h[i] = w == photon::kWholeShutter ? 0.5f * float(photon::kTimeBins) * binWidth : (float(w) + 0.5f) * binWidth;
  }
  std::nth_element(r.begin(), r.begin() + n / 2, r.end());
  std::nth_element(h.begin(), h.begin() + n / 2, h.end());
  return {r[n / 2], h[n / 2]};
}

BeamPassKernel beamKernelForPass(VolumeKernel first, int pass, float binWidth, float alpha) {
  const double s = volumeKernelScale(pass, alpha, 3);
  const double r = first.radius * s, hb = first.halfWindow * s / binWidth;  // h in bins
  BeamPassKernel k;
  // 2w + 1 whole bins nearest 2 hb; at least one bin.
  long w = std::max(0L, std::lround(hb - 0.5));
  double width = 2.0 * double(w) + 1.0;
  if (w > photon::kMaxWindowCode) {
    k.windowCode = photon::kWholeShutter;
    width = double(photon::kTimeBins);
  } else {
    k.windowCode = int(w);
  }
  k.halfWindow = float(0.5 * width * binWidth);
  k.radius = float(r * std::sqrt(2.0 * hb / width));  // r^2 x window = the schedule's
  return k;
}

VolumeKernel pointKernelForPass(VolumeKernel first, int pass, float binWidth, float alpha) {
  const double s = volumeKernelScale(pass, alpha, 4);
  double r = first.radius * s, h = first.halfWindow * s;
  if (h < binWidth && first.halfWindow > 0.0f) {
    r *= std::cbrt(h / binWidth);  // below a bin time cannot resolve more: keep r^3 h
    h = binWidth;
  }
  return {float(r), float(h)};
}

}  // namespace tdpm::estimate
