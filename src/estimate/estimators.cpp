// estimate/estimators.cpp — the non-template parts of the estimators: the
// per-thread gatherer's set-up and the clipped space-time volume of the 4D
// estimate.
#include "estimate/estimators.h"

#include <algorithm>

#include "core/error.h"

namespace tdpm::estimate {

Gatherer::Gatherer(const photon::KdTree& tree, const Options& options)
    : tree_(&tree), opt_(options), query_(std::max({options.k, options.ks, 1})) {
  TDPM_ASSERT(opt_.k > 0 && opt_.ks > 0, "estimate: k and k_s must be positive");
  TDPM_ASSERT(opt_.fraction > 0.0f && opt_.fraction <= 1.0f, "estimate: fraction must be in (0, 1]");
  TDPM_ASSERT(opt_.coneK >= 1.0f, "estimate: cone filter constant k must be >= 1");
  // The tree's variant is checked per call (knn / knn4 assert): a gatherer
  // over a 4D tree may be built with any options and used for spaceTime4D().
  bins_.resize(size_t(std::max(opt_.ks, opt_.k)) + photon::kSelectPadding);
  kept_.resize(size_t(std::max(opt_.ks, opt_.k)));
}

// The 4D estimate's volume (method.md section 4).
//
// Near x the surface is a plane; in its coordinates (u, v) and in time
// s = t' - t, the k nearest photons in the metric |dx|^2 + kappa s^2 lie in
//     u^2 + v^2 + kappa s^2 <= d^2,
// an ellipsoid of semi-axes d, d, d / sqrt(kappa). Its slice at time s is a
// disc of radius^2 d^2 - kappa s^2, so the volume between s = a and s = b
// (-d/sqrt(kappa) <= a <= b <= d/sqrt(kappa)) is
//     V = pi * integral_a^b (d^2 - kappa s^2) ds
//       = pi * [ d^2 (b - a) - kappa (b^3 - a^3) / 3 ].
// Unclipped (a = -b = d/sqrt(kappa)): V = 4/3 pi d^3 / sqrt(kappa), the
// ellipsoid. The estimate clips [a, b] to the time range of the photons
// found (their bins) and to the shutter: where photons cluster in time, no
// photon can lie outside that range, and counting that empty volume would
// blur time.
double clippedEllipsoidVolume(double d2, double kappa, double a, double b) {
  if (!(b > a) || !(d2 > 0.0) || !(kappa > 0.0)) return 0.0;
  double v = kPi * (d2 * (b - a) - kappa * (b * b * b - a * a * a) / 3.0);
  return v > 0.0 ? v : 0.0;
}

}  // namespace tdpm::estimate
