// import/spectrum.cpp — spectrum -> XYZ -> linear sRGB (import/spectrum.h).
#include "import/spectrum.h"

#include <algorithm>
#include <cmath>

namespace tdpm::spectrum {

using detail::kCie;
using detail::kCieRows;

double Piecewise::at(double nm) const {
  if (lambda.empty()) return 0;
  if (nm <= lambda.front()) return nm == lambda.front() || clampOutside ? value.front() : 0.0;
  if (nm >= lambda.back()) return nm == lambda.back() || clampOutside ? value.back() : 0.0;
  size_t i = size_t(std::upper_bound(lambda.begin(), lambda.end(), nm) - lambda.begin());
  double t = (nm - lambda[i - 1]) / (lambda[i] - lambda[i - 1]);
  return value[i - 1] + t * (value[i] - value[i - 1]);
}

double planck(double nm, double kelvin) {
  // 2019 SI values: h, c exact; kB exact.
  const double h = 6.62607015e-34, c = 299792458.0, kB = 1.380649e-23;
  double l = nm * 1e-9;
  return 2 * h * c * c / (std::pow(l, 5) * (std::exp(h * c / (l * kB * kelvin)) - 1));
}

double planckPeakNm(double kelvin) { return 2.897771955e6 / kelvin; }  // Wien's b, nm K

Piecewise blackbody(double kelvin) {
  // Sampled at 1 nm: the integration below reads it at 1 nm exactly.
  Piecewise s;
  double peak = planck(planckPeakNm(kelvin), kelvin);
  for (int nm = 360; nm <= 830; ++nm) {
    s.lambda.push_back(nm);
    s.value.push_back(planck(nm, kelvin) / peak);
  }
  return s;
}

namespace {

// The CIE row data at `nm` (360..830), linear between the 5 nm rows.
detail::CieRow cieAt(int nm) {
  int i = (nm - 360) / 5, f = (nm - 360) % 5;
  if (i >= kCieRows - 1) return kCie[kCieRows - 1];
  const detail::CieRow &a = kCie[i], &b = kCie[i + 1];
  double t = f / 5.0;
  return {a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), a.z + t * (b.z - a.z), a.d65 + t * (b.d65 - a.d65)};
}

template <class Weight>
Xyz integrate(const Piecewise& s, Weight weight) {
  Xyz c;
  double norm = 0;
  for (int nm = 360; nm <= 830; ++nm) {
    detail::CieRow r = cieAt(nm);
    double w = weight(r);
    double v = s.at(nm) * w;
    c.x += v * r.x;
    c.y += v * r.y;
    c.z += v * r.z;
    norm += w * r.y;
  }
  return {c.x / norm, c.y / norm, c.z / norm};
}

}  // namespace

Xyz xyzEqualEnergy(const Piecewise& s) {
  return integrate(s, [](const detail::CieRow&) { return 1.0; });
}

Xyz xyzUnderD65(const Piecewise& s) {
  return integrate(s, [](const detail::CieRow& r) { return r.d65; });
}

Xyz xyzOfD65() {
  Piecewise one{{300, 900}, {1, 1}, true};
  return xyzUnderD65(one);
}

Rgb xyzToLinearSrgb(const Xyz& c) {
  // M = [P diag(S)]^-1 where P's columns are the primaries' XYZ (x/y, 1,
  // (1-x-y)/y) and S scales them so that P S (1,1,1) is the white.
  struct M3 {
    double m[3][3];
  };
  static const M3 inv = [] {
    const double prim[3][2] = {{0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06}};  // BT.709 / sRGB
    double P[3][3];
    for (int j = 0; j < 3; ++j) {
      double x = prim[j][0], y = prim[j][1];
      P[0][j] = x / y;
      P[1][j] = 1;
      P[2][j] = (1 - x - y) / y;
    }
    auto inverse = [](const double a[3][3], double r[3][3]) {
      double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                   a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
          int i1 = (j + 1) % 3, i2 = (j + 2) % 3, j1 = (i + 1) % 3, j2 = (i + 2) % 3;
          r[i][j] = (a[i1][j1] * a[i2][j2] - a[i1][j2] * a[i2][j1]) / det;
        }
    };
    double Pi[3][3];
    inverse(P, Pi);
    Xyz w = xyzOfD65();
    double S[3];
    for (int i = 0; i < 3; ++i) S[i] = Pi[i][0] * w.x + Pi[i][1] * w.y + Pi[i][2] * w.z;
    double PS[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) PS[i][j] = P[i][j] * S[j];
    M3 out;
    inverse(PS, out.m);
    return out;
  }();
  const double v[3] = {c.x, c.y, c.z};
  double o[3];
  for (int i = 0; i < 3; ++i) o[i] = inv.m[i][0] * v[0] + inv.m[i][1] * v[1] + inv.m[i][2] * v[2];
  return {float(o[0]), float(o[1]), float(o[2])};
}

}  // namespace tdpm::spectrum
