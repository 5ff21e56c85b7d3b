// scene/environment.cpp — environment radiance, its luminance sampling and
// the equal-area to lat-long conversion.
#include "scene/environment.h"

#include <algorithm>
#include <cmath>

#include "image/read_image.h"
#include "sampling/warp.h"

namespace tdpm {

namespace {

constexpr float kTwoPi = 2.0f * kPi;

// The texel's (u, v) of a unit light-space direction: u = phi / 2pi with
// phi = atan2(y, x) in [0, 2pi), v = theta / pi (pbrt-v3's lat-long).
Vec2f latLongUv(Vec3f d) {
  float z = std::clamp(d.z, -1.0f, 1.0f);
  float phi = std::atan2(d.y, d.x);
  if (phi < 0) phi += kTwoPi;
  return {phi / kTwoPi, std::acos(z) / kPi};
}

Vec3f uvToDirection(float u, float v, float* sinTheta) {
  float theta = v * kPi, phi = u * kTwoPi;
  float s = std::sin(theta);
  *sinTheta = s;
  return {s * std::cos(phi), s * std::sin(phi), std::cos(theta)};
}

// Index of the cdf interval [cdf[i], cdf[i+1]) holding u (cdf ascending, n+1 entries).
int findInterval(const float* cdf, int n, float u) {
  const float* it = std::upper_bound(cdf, cdf + n + 1, u);
  return std::clamp(int(it - cdf) - 1, 0, n - 1);
}

Affine3f linearInverse(const Affine3f& m) {
  Affine3f lin = m;
  lin.m[0][3] = lin.m[1][3] = lin.m[2][3] = 0.0f;
  return lin.inverse();
}

}  // namespace

EnvironmentMap EnvironmentMap::constant(Rgb L, const Affine3f& lightToWorld) {
  EnvironmentMap e;
  e.constant_ = L;
  e.integral_ = L * (4.0f * kPi);
  e.toWorld_ = lightToWorld;
  e.toLight_ = linearInverse(lightToWorld);
  return e;
}

EnvironmentMap EnvironmentMap::fromLatLong(const image::ImageRgb& img, Rgb scale, const Affine3f& lightToWorld) {
  TDPM_ASSERT(!img.empty(), "environment map of zero size");
  EnvironmentMap e;
  e.width_ = img.width;
  e.height_ = img.height;
  e.texels_.resize(img.pixelCount());
  for (size_t i = 0; i < e.texels_.size(); ++i) e.texels_[i] = img.pixels[i] * scale;
  e.toWorld_ = lightToWorld;
  e.toLight_ = linearInverse(lightToWorld);
  e.buildDistribution();
  return e;
}

void EnvironmentMap::buildDistribution() {
  const int W = width_, H = height_;
  func_.assign(size_t(W) * size_t(H), 0.0f);
  colCdf_.assign(size_t(W + 1) * size_t(H), 0.0f);
  rowCdf_.assign(size_t(H + 1), 0.0f);
  double total = 0, dPhi = double(kTwoPi) / W;
  Rgb integral(0.0f);
  for (int y = 0; y < H; ++y) {
    double t0 = double(kPi) * y / H, t1 = double(kPi) * (y + 1) / H;
    float sinC = float(std::sin(0.5 * (t0 + t1)));
    float band = float(dPhi * (std::cos(t0) - std::cos(t1)));  // exact solid angle of a texel in this row
    double rowSum = 0;
    float* cdf = &colCdf_[size_t(y) * size_t(W + 1)];
    for (int x = 0; x < W; ++x) {
      const Rgb& t = texels_[size_t(y) * W + x];
      integral += t * band;
      float f = std::max(0.0f, t.luminance()) * sinC;
      func_[size_t(y) * W + x] = f;
      rowSum += f;
      cdf[x + 1] = float(rowSum);
    }
    for (int x = 1; x <= W; ++x) cdf[x] = rowSum > 0 ? float(cdf[x] / rowSum) : float(x) / W;
    cdf[W] = 1.0f;
    total += rowSum;
    rowCdf_[size_t(y) + 1] = float(total);
  }
  for (int y = 1; y <= H; ++y) rowCdf_[size_t(y)] = total > 0 ? float(rowCdf_[size_t(y)] / total) : float(y) / H;
  rowCdf_[size_t(H)] = 1.0f;
  meanFunc_ = float(total / (double(W) * H));
  integral_ = integral;
}

size_t EnvironmentMap::texelIndex(Vec3f local, float* sinTheta) const {
  Vec2f uv = latLongUv(local);
  int x = std::clamp(int(uv.x * width_), 0, width_ - 1);
  int y = std::clamp(int(uv.y * height_), 0, height_ - 1);
  *sinTheta = std::sqrt(local.x * local.x + local.y * local.y);  // accurate near the poles, unlike 1 - z^2
  return size_t(y) * size_t(width_) + size_t(x);
}

Rgb EnvironmentMap::radiance(Vec3f w) const {
  if (isConstant()) return constant_;
  float s;
  return texels_[texelIndex(normalize(toLight_.vector(w)), &s)];
}

float EnvironmentMap::pdf(Vec3f w) const {
  if (isConstant()) return constant_.maxComponent() > 0 ? kUniformSpherePdf : 0.0f;
  if (!(meanFunc_ > 0)) return 0.0f;
  float s;
  size_t i = texelIndex(normalize(toLight_.vector(w)), &s);
  if (!(s > 0)) return 0.0f;
  return func_[i] / meanFunc_ / (2.0f * kPi * kPi * s);
}

bool EnvironmentMap::sample(Vec2f u, Vec3f& w, Rgb& L, float& pdf) const {
  if (isConstant()) {
    if (!(constant_.maxComponent() > 0)) return false;
    w = squareToUniformSphere(u);
    L = constant_;
    pdf = kUniformSpherePdf;
    return true;
  }
  if (!(meanFunc_ > 0)) return false;
  int y = findInterval(rowCdf_.data(), height_, u.y);
  const float* cdf = &colCdf_[size_t(y) * size_t(width_ + 1)];
  int x = findInterval(cdf, width_, u.x);
  float dy = rowCdf_[size_t(y) + 1] - rowCdf_[size_t(y)], dx = cdf[x + 1] - cdf[x];
  float fy = dy > 0 ? (u.y - rowCdf_[size_t(y)]) / dy : 0.5f, fx = dx > 0 ? (u.x - cdf[x]) / dx : 0.5f;
  // Inside the chosen texel (its radiance and density are the ones returned).
  constexpr float kBelowOne = 0x1.fffffep-1f;
  float uu = (float(x) + std::clamp(fx, 0.0f, kBelowOne)) / float(width_);
  float vv = (float(y) + std::clamp(fy, 0.0f, kBelowOne)) / float(height_);
  float s;
  Vec3f local = uvToDirection(uu, vv, &s);
  size_t i = size_t(y) * size_t(width_) + size_t(x);
  if (!(s > 0) || !(func_[i] > 0)) return false;
  w = normalize(toWorld_.vector(local));
  L = texels_[i];
  pdf = func_[i] / meanFunc_ / (2.0f * kPi * kPi * s);
  return pdf > 0 && std::isfinite(pdf);
}

// ---- pbrt-v4's equal-area octahedral map ----

Vec3f equalAreaSquareToSphere(Vec2f p) {
  float u = 2 * p.x - 1, v = 2 * p.y - 1;
  float up = std::fabs(u), vp = std::fabs(v);
  float signedDistance = 1 - (up + vp);
  float d = std::fabs(signedDistance);
  float r = 1 - d;
  float phi = (r == 0 ? 1 : (vp - up) / r + 1) * kPi / 4;
  float z = std::copysign(1 - r * r, signedDistance);
  float cosPhi = std::copysign(std::cos(phi), u), sinPhi = std::copysign(std::sin(phi), v);
  float k = r * std::sqrt(std::max(0.0f, 2 - r * r));
  return {cosPhi * k, sinPhi * k, z};
}

Vec2f equalAreaSphereToSquare(Vec3f d) {
  float x = std::fabs(d.x), y = std::fabs(d.y), z = std::fabs(d.z);
  float r = std::sqrt(std::max(0.0f, 1 - z));
  float a = std::max(x, y), b = std::min(x, y);
  b = a == 0 ? 0 : b / a;
  float phi = std::atan(b) * (2.0f / kPi);
  if (x < y) phi = 1 - phi;
  float v = phi * r, u = r - v;
  if (d.z < 0) {
    std::swap(u, v);
    u = 1 - u;
    v = 1 - v;
  }
  u = std::copysign(u, d.x);
  v = std::copysign(v, d.y);
  return {0.5f * (u + 1), 0.5f * (v + 1)};
}

image::ImageRgb equalAreaToLatLong(const image::ImageRgb& sq) {
  const int n = sq.width;
  image::ImageRgb out(2 * n, n);
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x) {
      float s;
      Vec3f d = uvToDirection((x + 0.5f) / out.width, (y + 0.5f) / out.height, &s);
      Vec2f p = equalAreaSphereToSquare(d);
      int px = std::clamp(int(p.x * n), 0, n - 1), py = std::clamp(int(p.y * n), 0, n - 1);
      out.at(x, y) = sq.at(px, py);
    }
  return out;
}

std::shared_ptr<const image::ImageRgb> loadEnvironmentMap(const std::string& path, bool equalArea,
                                                          std::string* problem) {
  image::ImageRgb img;
  try {
    img = image::readImage(path).color;
  } catch (const Error& e) {
    *problem = e.what();
    return nullptr;
  }
  if (img.empty()) {
    *problem = path + ": the environment map has no texels (" + std::to_string(img.width) + " x " +
               std::to_string(img.height) + ")";
    return nullptr;
  }
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const Rgb& c = img.at(x, y);
      if (!(c.r >= 0 && c.g >= 0 && c.b >= 0) || !isFinite(c)) {
        *problem = path + ": texel (" + std::to_string(x) + ", " + std::to_string(y) + ") is " + std::to_string(c.r) +
                   " " + std::to_string(c.g) + " " + std::to_string(c.b) +
                   ": environment radiance must be finite and non-negative";
        return nullptr;
      }
    }
  if (equalArea) {
    if (img.width != img.height) {
      *problem = path + ": an equal-area (pbrt-v4) environment map must be square, got " + std::to_string(img.width) +
                 " x " + std::to_string(img.height);
      return nullptr;
    }
    img = equalAreaToLatLong(img);
  }
  return std::make_shared<const image::ImageRgb>(std::move(img));
}

double upperHemisphereIlluminance(const image::ImageRgb& img) {
  const int W = img.width, H = img.height;
  double sum = 0, dPhi = 2.0 * double(kPi) / W;
  for (int y = 0; y < H; ++y) {
    double t0 = double(kPi) * y / H, t1 = double(kPi) * (y + 1) / H;
    if (t0 >= double(kPi) / 2) break;
    t1 = std::min(t1, double(kPi) / 2);
    // integral of cos(theta) sin(theta) over [t0, t1] = (sin^2 t1 - sin^2 t0) / 2
    double w = dPhi * 0.5 * (std::sin(t1) * std::sin(t1) - std::sin(t0) * std::sin(t0));
    for (int x = 0; x < W; ++x) sum += double(img.at(x, y).luminance()) * w;
  }
  return sum;
}

}  // namespace tdpm
