// estimate/estimators.cpp — the non-template parts of the estimators: the
// per-thread gatherer's set-up, the clipped space-time volume of the 4D
// estimate and the two-pass small-count factor.
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
// ellipsoid. The estimate clips [a, b] to the shutter only, where photons
// can be: clipping it to the photons' own time range (as it once did)
// divides by a volume the photons define and overestimates where they are
// few (docs/photon-map.md, "Few photons").
double clippedEllipsoidVolume(double d2, double kappa, double a, double b) {
  if (!(b > a) || !(d2 > 0.0) || !(kappa > 0.0)) return 0.0;
  double v = kPi * (d2 * (b - a) - kappa * (b * b * b - a * a * a) / 3.0);
  return v > 0.0 ? v : 0.0;
}


// The two-pass small-count factor (header; docs/photon-map.md, "Few
// photons"). The window grows outward from the query in a fixed order of
// bins; give the photons of each step virtual positions uniform over the
// step's measure. They are then a Poisson (or, given the candidates, a
// binomial) process in measure, the window closes at the step holding the
// m-th arrival X_m, and (m - 1) / X_m has mean the rate for any m >= 2 (the
// continuous k-NN result: X_m ~ Gamma(m), E[1/X_m] = rate / (m - 1)). X_m is
// not known, only that it is the j-th of the C photons of the last step:
// X_m = a + w B, B ~ Beta(j, C - j + 1), and its mean inverse is taken
// exactly for a = 0 (E[1/B] = C / (j - 1)) and to second order otherwise
// (a >= 1 bin, so the third-order term is below 0.3% for one-bin steps).
// The estimate is the mean photon of the window times that rate.
double timeWindowCorrection(int m, int windowBins, int kept, int prevBins, int prevKept) {
  const double a = double(prevBins), w = double(windowBins - prevBins);
  const int C = kept - prevKept, j = m - prevKept;
  if (m < 2 || C < 1 || j < 1 || j > C || !(w > 0.0) || kept < 1) return 1.0;  // not a photon-defined window
  double g;
  if (a == 0.0) {
    if (j < 2) return 1.0;
    g = double(C) / (double(j - 1) * w);
  } else {
    const double c1 = double(C + 1);
    const double mu = a + w * double(j) / c1;
    const double var = w * w * double(j) * double(C - j + 1) / (c1 * c1 * double(C + 2));
    g = 1.0 / mu + var / (mu * mu * mu);
  }
  return double(m - 1) * g * double(windowBins) / double(kept);
}

}  // namespace tdpm::estimate
