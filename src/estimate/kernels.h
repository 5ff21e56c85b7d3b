// estimate/kernels.h — smoothing kernels of the density estimates and their
// normalisations (method.md section 3). Each kernel is a small type so that
// the gather loop is instantiated per kernel (no branch or call per photon).
//
//  K1 (space), argument rho = |x_p - x| / r in [0, 1], normalised so that
//     the integral over the unit disc is pi (the disc area):
//       uniform       K1 = 1
//       Epanechnikov  K1 = 2 (1 - rho^2)          (int 2(1-rho^2) 2 pi rho = pi)
//       cone (Jensen) K1 = (1 - rho / k) / (1 - 2 / (3k)), k >= 1
//                     (int (1 - rho/k) 2 pi rho drho = pi (1 - 2/(3k)))
//  K2 (time), argument y = (t_p - t) / h in [-1, 1], h the half-width of
//     the window, normalised so that the integral over [-1, 1] is 2:
//       uniform       K2 = 1
//       Epanechnikov  K2 = 1.5 (1 - y^2)
//     When the window is clipped to [a, b] (shutter ends, or the kept bins
//     not centred on t), the estimate divides by the integral of K2 over
//     [a, b] instead of 2: uniform gives the clipped length, and any kernel
//     stays unbiased for a density constant over the window.
//     A photon's time is known only to its 8-bit bin, over which it is
//     uniform; so a photon weighs the mean of K2 over its bin, [y0, y1]
//     (exact for uniform; for Epanechnikov the mean of a quadratic).
#pragma once
#include <cmath>

namespace tdpm::estimate {

enum class SpaceKernel : unsigned char { Uniform, Cone, Epanechnikov };
enum class TimeKernel : unsigned char { Uniform, Epanechnikov };

struct K1Uniform {
  float operator()(float /*rho2*/) const { return 1.0f; }
};
struct K1Epanechnikov {
  float operator()(float rho2) const { return 2.0f * (1.0f - rho2); }
};
struct K1Cone {
  float invK, norm;  // 1/k and 1 / (1 - 2/(3k))
  explicit K1Cone(float k) : invK(1.0f / k), norm(1.0f / (1.0f - 2.0f / (3.0f * k))) {}
  float operator()(float rho2) const { return (1.0f - std::sqrt(rho2) * invK) * norm; }
};

struct K2Uniform {
  static float binMean(float /*y0*/, float /*y1*/) { return 1.0f; }
  static float integral(float a, float b) { return b - a; }
};
struct K2Epanechnikov {
  // mean of 1.5 (1 - y^2) over [y0, y1]
  static float binMean(float y0, float y1) { return 1.5f * (1.0f - (y0 * y0 + y0 * y1 + y1 * y1) * (1.0f / 3.0f)); }
  static float integral(float a, float b) { return 1.5f * ((b - a) - (b * b * b - a * a * a) * (1.0f / 3.0f)); }
};

}  // namespace tdpm::estimate
