// scene/environment.h — an environment light's radiance over directions:
// a constant, or a lat-long map in pbrt-v3's convention (light space +z is
// row 0, phi = atan2(y, x) runs along the row), turned into the world by a
// light-to-world rotation (and mirror). Owns the map's importance sampling:
// a 2D piecewise-constant distribution over (u, v) by luminance x sin(theta)
// in flat arrays, with densities in solid angle. Also the conversion of
// pbrt-v4's equal-area square maps (Clarberg's mapping) to lat-long.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "image/image.h"
#include "math/transform.h"
#include "math/vec.h"

namespace tdpm {

class EnvironmentMap {
 public:
  // radiance = L in every direction.
  static EnvironmentMap constant(Rgb L, const Affine3f& lightToWorld);
  // radiance = scale x the texel; `latLong` has row 0 at theta = 0 (+z).
  static EnvironmentMap fromLatLong(const image::ImageRgb& latLong, Rgb scale, const Affine3f& lightToWorld);

  // Radiance arriving from world direction `w` (unit, pointing away from
  // the scene toward the sky).
  Rgb radiance(Vec3f w) const;
  // Solid-angle density with which sample() picks w.
  float pdf(Vec3f w) const;
  // A direction toward the sky drawn by luminance; false when the map is
  // black. Returns its radiance and solid-angle density.
  bool sample(Vec2f u, Vec3f& w, Rgb& L, float& pdf) const;
  // Integral of the radiance over the sphere of directions (W m^-2): the
  // flux through a disc of area A perpendicular to each direction is A times it.
  Rgb integral() const { return integral_; }
  bool isConstant() const { return width_ == 0; }

 private:
  int width_ = 0, height_ = 0;   // 0: constant
  Rgb constant_{0.0f};
  std::vector<Rgb> texels_;      // width x height, row-major, scaled
  std::vector<float> func_;      // luminance x sin(theta at the row's centre)
  std::vector<float> colCdf_;    // height rows of width + 1 entries
  std::vector<float> rowCdf_;    // height + 1
  float meanFunc_ = 0.0f;        // average of func_ over the texels
  Rgb integral_{0.0f};
  Affine3f toWorld_, toLight_;   // linear parts used only

  size_t texelIndex(Vec3f local, float* sinTheta) const;
  void buildDistribution();
};

// pbrt-v4's equal-area square to the unit sphere and back (Clarberg 2008;
// pbrt-v4 util/math.cpp): the square [0,1]^2, centre = +z.
Vec3f equalAreaSquareToSphere(Vec2f p);
Vec2f equalAreaSphereToSquare(Vec3f d);
// Resamples a square equal-area map to lat-long, 2N x N for an N x N map,
// nearest texel (each lat-long texel is smaller than an equal-area one).
image::ImageRgb equalAreaToLatLong(const image::ImageRgb& square);

// Reads an environment map (EXR, PFM, HDR, PNG) as lat-long texels,
// converting a pbrt-v4 equal-area map. Null, with *problem = "<path>: ...",
// when the file is missing or unreadable, has no texels, holds a negative
// or non-finite value (the first one named), or is equal-area but not square.
std::shared_ptr<const image::ImageRgb> loadEnvironmentMap(const std::string& path, bool equalArea,
                                                          std::string* problem);

// Integral over the light-space upper hemisphere (z > 0) of the luminance
// times cos(theta), of a lat-long map (pbrt-v4's k_e for "illuminance").
double upperHemisphereIlluminance(const image::ImageRgb& latLong);

}  // namespace tdpm
