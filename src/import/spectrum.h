// import/spectrum.h — spectra reduced to linear sRGB once, at load: tdpm is
// an RGB renderer, so a spectral input (pbrt's "spectrum" and "blackbody"
// values, .spd files, named spectra) becomes the RGB triple that the
// spectrum's CIE 1931 2° XYZ maps to, under the white each pbrt version
// implies (docs/pbrt-import.md, "Spectra"). Tables: spectrum_tables.cpp.
#pragma once
#include <string>
#include <vector>

#include "math/vec.h"

namespace tdpm::spectrum {

struct Xyz {
  double x = 0, y = 0, z = 0;
};

// A piecewise-linear spectrum through (lambda[i] nm, value[i]), lambda
// strictly increasing. Outside [front, back]: pbrt-v4 reads 0, pbrt-v3
// (InterpolateSpectrumSamples) the end values.
struct Piecewise {
  std::vector<double> lambda, value;
  bool clampOutside = false;  // true: pbrt-v3's end values; false: pbrt-v4's zero
  double at(double nm) const;
};

// Planck's law: spectral radiance of a black body at `kelvin`, W / (m^2 sr m).
double planck(double nm, double kelvin);
// Wien's displacement law: the wavelength of Planck's peak, nm.
double planckPeakNm(double kelvin);
// A black body scaled so its peak is 1 (pbrt-v3 BlackbodyNormalized and
// pbrt-v4 BlackbodySpectrum both normalise by the peak).
Piecewise blackbody(double kelvin);

// CIE 1931 XYZ of a spectrum, integrated at 1 nm over 360-830 nm against the
// 5 nm tables interpolated linearly, normalised so that:
//   equal energy: a constant spectrum 1 has Y = 1 (white = illuminant E);
//   under D65:    the spectrum is a reflectance lit by D65, so a constant
//                 reflectance 1 has the XYZ of D65 with Y = 1.
Xyz xyzEqualEnergy(const Piecewise& s);
Xyz xyzUnderD65(const Piecewise& s);
Xyz xyzOfD65();  // Y = 1

// Linear sRGB (ITU-R BT.709 primaries) from XYZ, the matrix built from the
// primaries' chromaticities and the white of xyzOfD65(), so D65 (and a grey
// reflectance under it) is exactly grey.
Rgb xyzToLinearSrgb(const Xyz& c);
inline Xyz chromaticity(const Xyz& c) {
  double s = c.x + c.y + c.z;
  return {c.x / s, c.y / s, c.y};
}

namespace detail {
constexpr int kCieRows = 95;  // 360, 365, ..., 830 nm
struct CieRow {
  double x, y, z, d65;
};
extern const CieRow kCie[kCieRows];
}  // namespace detail

}  // namespace tdpm::spectrum
