// media/medium.cpp — building media, grid lookups, transmittance (closed
// form / ratio tracking) and free flight (spectral tracking); the
// estimators are derived in medium.h and docs/media.md.
#include "media/medium.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tdpm::media {

namespace {

float maxOf(Rgb c) { return std::max({c.r, c.g, c.b}); }

// Below this transmittance, ratio tracking plays Russian roulette with
// survival probability max_c T_c (unbiased; saves the steps through a
// dense cloud that could no longer change the answer much).
constexpr float kRouletteTransmittance = 0.1f;

// The segment of the ray inside the medium's support, in world distance:
// [s0, s1] within [0, tMax]; grid-space origin and direction out.
bool gridSegment(const Medium& m, Vec3f o, Vec3f d, float tMax, float time01, Vec3f& og, Vec3f& dg, float& s0,
                 float& s1) {
  const Affine3f gfw = m.moving ? m.gridFromLocal * m.objectMotion.atNormalized(time01).inverse() : m.gridFromWorld;
  og = gfw.point(o);
  dg = gfw.vector(d);
  s0 = 0.0f;
  s1 = tMax;
  for (int a = 0; a < 3; ++a) {
    if (dg[a] == 0.0f) {
      if (og[a] < m.bounds.lo[a] || og[a] > m.bounds.hi[a]) return false;
      continue;
    }
    float inv = 1.0f / dg[a];
    float tn = (m.bounds.lo[a] - og[a]) * inv, tf = (m.bounds.hi[a] - og[a]) * inv;
    if (tn > tf) std::swap(tn, tf);
    s0 = std::max(s0, tn);
    s1 = std::min(s1, tf);
    if (s0 >= s1) return false;
  }
  return true;
}

// The medium's (sigma_a, sigma_s) at a point of the segment.
struct Coefficients {
  Rgb a, s;
};

Coefficients at(const Medium& m, Vec3f og, Vec3f dg, float s) {
  if (m.homogeneous()) return {m.sigmaA, m.sigmaS};
  float rho = gridDensity(m, og + dg * s);
  return {m.sigmaA * rho, m.sigmaS * rho};
}

float exponential(Rng& rng, float rate) { return -std::log1p(-rng.uniform()) / rate; }

}  // namespace

Medium makeMedium(const scene::MediumDesc& d, const Motion* object, std::shared_ptr<const std::vector<float>> shared) {
  Medium m;
  m.sigmaA = d.sigmaA * d.scale;
  m.sigmaS = d.sigmaS * d.scale;
  m.sigmaT = m.sigmaA + m.sigmaS;
  m.g = d.g;
  m.majorant = maxOf(m.sigmaT);
  m.grey = m.sigmaA.r == m.sigmaA.g && m.sigmaA.g == m.sigmaA.b && m.sigmaS.r == m.sigmaS.g && m.sigmaS.g == m.sigmaS.b;
  if (d.type == scene::MediumDesc::Type::Homogeneous) return m;
  m.kind = Medium::Kind::Grid;
  m.nx = d.grid.nx;
  m.ny = d.grid.ny;
  m.nz = d.grid.nz;
  m.density = shared ? std::move(shared) : std::make_shared<const std::vector<float>>(d.grid.density);
  float maxDensity = 0.0f;
  for (float v : *m.density) maxDensity = std::max(maxDensity, v);
  m.majorant *= maxDensity;
  m.bounds = d.grid.bounds;
  Vec3f size = m.bounds.diagonal();
  m.cellsPerUnit = {float(m.nx) / size.x, float(m.ny) / size.y, float(m.nz) / size.z};
  Affine3f placement = d.placement.matrix();  // grid -> world, or grid -> object
  m.gridFromLocal = placement.inverse();
  if (object && object->moving()) {
    m.moving = true;
    m.objectMotion = *object;
  } else {
    Affine3f objectToWorld = object ? object->step(0) : Affine3f::identity();
    m.gridFromWorld = (objectToWorld * placement).inverse();
  }
  return m;
}

float gridDensity(const Medium& m, Vec3f p) {
  if (!m.bounds.contains(p)) return 0.0f;
  // Continuous index with cell centres at integers.
  float fx = (p.x - m.bounds.lo.x) * m.cellsPerUnit.x - 0.5f;
  float fy = (p.y - m.bounds.lo.y) * m.cellsPerUnit.y - 0.5f;
  float fz = (p.z - m.bounds.lo.z) * m.cellsPerUnit.z - 0.5f;
  int ix = int(std::floor(fx)), iy = int(std::floor(fy)), iz = int(std::floor(fz));
  float dx = fx - float(ix), dy = fy - float(iy), dz = fz - float(iz);
  const std::vector<float>& v = *m.density;
  auto cell = [&](int x, int y, int z) -> float {
    if (x < 0 || y < 0 || z < 0 || x >= m.nx || y >= m.ny || z >= m.nz) return 0.0f;
    return v[(size_t(z) * size_t(m.ny) + size_t(y)) * size_t(m.nx) + size_t(x)];
  };
  float c00 = cell(ix, iy, iz) * (1 - dx) + cell(ix + 1, iy, iz) * dx;
  float c10 = cell(ix, iy + 1, iz) * (1 - dx) + cell(ix + 1, iy + 1, iz) * dx;
  float c01 = cell(ix, iy, iz + 1) * (1 - dx) + cell(ix + 1, iy, iz + 1) * dx;
  float c11 = cell(ix, iy + 1, iz + 1) * (1 - dx) + cell(ix + 1, iy + 1, iz + 1) * dx;
  return (c00 * (1 - dy) + c10 * dy) * (1 - dz) + (c01 * (1 - dy) + c11 * dy) * dz;
}

Rgb transmittance(const Medium& m, Vec3f o, Vec3f d, float tMax, float time01, Rng& rng) {
  if (m.majorant <= 0.0f) return Rgb(1.0f);
  if (m.homogeneous()) {
    if (std::isinf(tMax)) return Rgb(m.sigmaT.r > 0 ? 0.0f : 1.0f, m.sigmaT.g > 0 ? 0.0f : 1.0f, m.sigmaT.b > 0 ? 0.0f : 1.0f);
    return {std::exp(-m.sigmaT.r * tMax), std::exp(-m.sigmaT.g * tMax), std::exp(-m.sigmaT.b * tMax)};
  }
  Vec3f og, dg;
  float s, s1;
  if (!gridSegment(m, o, d, tMax, time01, og, dg, s, s1)) return Rgb(1.0f);
  // Ratio tracking: T_c = prod over tentative collisions of (1 - sigma_t,c / sigma_bar).
  Rgb T(1.0f);
  const float inv = 1.0f / m.majorant;
  for (;;) {
    s += exponential(rng, m.majorant);
    if (s >= s1) return T;
    Coefficients c = at(m, og, dg, s);
    Rgb st = c.a + c.s;
    T = T * Rgb(1.0f - st.r * inv, 1.0f - st.g * inv, 1.0f - st.b * inv);
    float q = maxOf(T);
    if (q < kRouletteTransmittance) {
      if (q <= 0.0f || rng.uniform() >= q) return Rgb(0.0f);
      T = T / q;
    }
  }
}

FreeFlight sampleFreeFlight(const Medium& m, Vec3f o, Vec3f d, float tMax, float time01, Rng& rng, Rgb& beta) {
  FreeFlight out;
  if (m.majorant <= 0.0f) return out;
  Vec3f og{0.0f}, dg{0.0f};
  float s = 0.0f, s1 = tMax;
  if (!m.homogeneous() && !gridSegment(m, o, d, tMax, time01, og, dg, s, s1)) return out;
  const float sb = m.majorant;
  for (;;) {
    s += exponential(rng, sb);
    if (!(s < s1)) return out;  // escape (also for s1 = inf never reached: s is finite)
    Coefficients c = at(m, og, dg, s);
    if (m.grey) {  // delta tracking: absorb, scatter or go on (null) by the grey coefficients
      float u = rng.uniform() * sb;
      if (u < c.a.r) out.event = FreeFlight::Event::Absorb;
      else if (u < c.a.r + c.s.r) out.event = FreeFlight::Event::Scatter;
      else continue;
      out.t = s;
      return out;
    }
    Rgb sn(std::max(0.0f, sb - c.a.r - c.s.r), std::max(0.0f, sb - c.a.g - c.s.g), std::max(0.0f, sb - c.a.b - c.s.b));
    float pa = maxOf(beta * c.a), ps = maxOf(beta * c.s), pn = maxOf(beta * sn);
    float sum = pa + ps + pn;
    if (!(sum > 0.0f)) {
      out.event = FreeFlight::Event::Absorb;
      return out;
    }
    float u = rng.uniform() * sum;
    if (u < pa) {
      out.event = FreeFlight::Event::Absorb;
      return out;
    }
    if (u < pa + ps) {
      beta = beta * c.s * (sum / (sb * ps));
      out.event = FreeFlight::Event::Scatter;
      out.t = s;
      return out;
    }
    beta = beta * sn * (sum / (sb * pn));
  }
}

}  // namespace tdpm::media
