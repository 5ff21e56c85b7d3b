// media/medium.cpp — building media (and a grid's majorant grid), grid
// lookups, the DDA over the majorant grid, transmittance (closed form /
// ratio tracking) and free flight (spectral tracking); the estimators are
// derived in medium.h and docs/media.md.
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

// The density samples (cell centres) whose trilinear footprint reaches
// majorant cell i of m along an axis with n density cells: the continuous
// index of the cell's extent is [i n / m - 0.5, (i + 1) n / m - 0.5]; a point
// there reads samples floor(f) and floor(f) + 1. Padded by 0.01 index units
// so rounding in the DDA (a collision a hair past the cell's edge) cannot
// read a sample the bound missed.
void footprint(int i, int m, int n, int& lo, int& hi) {
  double fa = double(i) * n / m - 0.5 - 0.01, fb = double(i + 1) * n / m - 0.5 + 0.01;
  lo = std::max(0, int(std::floor(fa)));
  hi = std::min(n - 1, int(std::floor(fb)) + 1);
}

void buildMajorantGrid(Medium& m, int cells) {
  m.mx = std::clamp(cells, 1, m.nx);
  m.my = std::clamp(cells, 1, m.ny);
  m.mz = std::clamp(cells, 1, m.nz);
  const float sigmaT = maxOf(m.sigmaT);
  const std::vector<float>& v = *m.density;
  std::vector<float> out(size_t(m.mx) * size_t(m.my) * size_t(m.mz));
  for (int k = 0; k < m.mz; ++k)
    for (int j = 0; j < m.my; ++j)
      for (int i = 0; i < m.mx; ++i) {
        int x0, x1, y0, y1, z0, z1;
        footprint(i, m.mx, m.nx, x0, x1);
        footprint(j, m.my, m.ny, y0, y1);
        footprint(k, m.mz, m.nz, z0, z1);
        float mx = 0.0f;
        for (int z = z0; z <= z1; ++z)
          for (int y = y0; y <= y1; ++y) {
            const float* row = v.data() + (size_t(z) * size_t(m.ny) + size_t(y)) * size_t(m.nx);
            for (int x = x0; x <= x1; ++x) mx = std::max(mx, row[x]);
          }
        // The same product as the global majorant's, so one cell reproduces it exactly.
        out[(size_t(k) * size_t(m.my) + size_t(j)) * size_t(m.mx) + size_t(i)] = sigmaT * mx;
      }
  // Where the cells' bounds average at least half the global one the grid
  // saves few null collisions and its DDA steps cost more than they save
  // (bench_media.cpp, `dense:1`: a uniform grid tracked 1.8-2.1x slower
  // through 16^3 cells than with one): one cell, the global majorant.
  double mean = 0.0;
  for (float c : out) mean += c;
  mean /= double(out.size());
  if (out.size() > 1 && mean >= 0.5 * double(sigmaT) * double(*std::max_element(v.begin(), v.end()))) {
    m.mx = m.my = m.mz = 1;
    out.assign(1, sigmaT * *std::max_element(v.begin(), v.end()));
  }
  m.majorants = std::make_shared<const std::vector<float>>(std::move(out));
  Vec3f size = m.bounds.diagonal();
  m.majorantCellsPerUnit = {float(m.mx) / size.x, float(m.my) / size.y, float(m.mz) / size.z};
}

// The majorant grid's cells along a grid-space segment og + s dg, s in
// [s0, s1] (already clipped to the bounds), in order: each call gives the
// next cell's [a, b] in world distance and its sigma_bar (Amanatides and
// Woo's DDA). The last cell along an axis has no exit plane of its own (the
// bounds clipped the segment there), so the walk ends exactly at s1 and a
// 1^3 grid yields the one segment [s0, s1] of the global majorant.
class MajorantWalk {
 public:
  MajorantWalk(const Medium& m, Vec3f og, Vec3f dg, float s0, float s1) : v_(m.majorants->data()), s_(s0), s1_(s1) {
    const int res[3] = {m.mx, m.my, m.mz};
    const Vec3f size = m.bounds.diagonal();
    const Vec3f p = og + dg * s0;
    stride_[0] = 1;
    stride_[1] = m.mx;
    stride_[2] = m.mx * m.my;
    index_ = 0;
    for (int a = 0; a < 3; ++a) {
      int c = std::clamp(int(std::floor((p[a] - m.bounds.lo[a]) * m.majorantCellsPerUnit[a])), 0, res[a] - 1);
      index_ += c * stride_[a];
      left_[a] = 0;
      next_[a] = std::numeric_limits<float>::infinity();
      if (dg[a] == 0.0f) continue;
      const bool up = dg[a] > 0.0f;
      left_[a] = up ? res[a] - 1 - c : c;  // cell boundaries still to cross along a
      if (up) step_[a] = stride_[a];
      else step_[a] = -stride_[a];
      const float w = size[a] / float(res[a]);
      const float plane = m.bounds.lo[a] + float(c + (up ? 1 : 0)) * w;
      if (left_[a] > 0) next_[a] = s0 + (plane - p[a]) / dg[a];
      delta_[a] = w / std::fabs(dg[a]);
    }
  }

  bool next(float& a, float& b, float& sigmaBar) {
    if (!(s_ < s1_)) return false;
    const int ax = next_[0] < next_[1] ? (next_[0] < next_[2] ? 0 : 2) : (next_[1] < next_[2] ? 1 : 2);
    a = s_;
    b = std::min(std::max(next_[ax], s_), s1_);
    sigmaBar = v_[index_];
    s_ = b;
    if (b < s1_) {
      index_ += step_[ax];
      next_[ax] = --left_[ax] > 0 ? next_[ax] + delta_[ax] : std::numeric_limits<float>::infinity();
    }
    return true;
  }

 private:
  const float* v_;
  float s_, s1_;
  float next_[3], delta_[3] = {0, 0, 0};
  int stride_[3], step_[3] = {0, 0, 0}, left_[3];
  int index_;
};

// One tentative collision at s with local majorant sb and the medium's
// coefficients c there: true when the flight ends there (out filled),
// false for a null collision (beta updated in chromatic media).
bool collide(const Medium& m, const Coefficients& c, float sb, float s, Rng& rng, Rgb& beta, FreeFlight& out) {
  if (m.grey) {  // delta tracking: absorb, scatter or go on (null) by the grey coefficients
    float u = rng.uniform() * sb;
    if (u < c.a.r) out.event = FreeFlight::Event::Absorb;
    else if (u < c.a.r + c.s.r) out.event = FreeFlight::Event::Scatter;
    else return false;
    out.t = s;
    return true;
  }
  Rgb sn(std::max(0.0f, sb - c.a.r - c.s.r), std::max(0.0f, sb - c.a.g - c.s.g), std::max(0.0f, sb - c.a.b - c.s.b));
  float pa = maxOf(beta * c.a), ps = maxOf(beta * c.s), pn = maxOf(beta * sn);
  float sum = pa + ps + pn;
  if (!(sum > 0.0f)) {
    out.event = FreeFlight::Event::Absorb;
    return true;
  }
  float u = rng.uniform() * sum;
  if (u < pa) {
    out.event = FreeFlight::Event::Absorb;
    return true;
  }
  if (u < pa + ps) {
    beta = beta * c.s * (sum / (sb * ps));
    out.event = FreeFlight::Event::Scatter;
    out.t = s;
    return true;
  }
  beta = beta * sn * (sum / (sb * pn));
  return false;
}

}  // namespace

Medium makeMedium(const scene::MediumDesc& d, const Motion* object, std::shared_ptr<const std::vector<float>> shared,
                  int majorantCells) {
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
  buildMajorantGrid(m, majorantCells);
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
  float s0, s1;
  if (!gridSegment(m, o, d, tMax, time01, og, dg, s0, s1)) return Rgb(1.0f);
  // Ratio tracking, cell by cell of the majorant grid:
  // T_c = prod over tentative collisions of (1 - sigma_t,c / sigma_bar_cell).
  Rgb T(1.0f);
  MajorantWalk walk(m, og, dg, s0, s1);
  float a, b, sb;
  while (walk.next(a, b, sb)) {
    if (!(sb > 0.0f)) continue;  // an empty cell: no collisions, T unchanged
    const float inv = 1.0f / sb;
    for (float s = a;;) {
      s += exponential(rng, sb);
      if (s >= b) break;
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
  return T;
}

FreeFlight sampleFreeFlight(const Medium& m, Vec3f o, Vec3f d, float tMax, float time01, Rng& rng, Rgb& beta) {
  FreeFlight out;
  if (m.majorant <= 0.0f) return out;
  if (m.homogeneous()) {  // one majorant, sigma_bar = max_c sigma_t,c: exponential sampling, never a march
    for (float s = 0.0f;;) {
      s += exponential(rng, m.majorant);
      if (!(s < tMax)) return out;  // escape (also for tMax = inf never reached: s is finite)
      if (collide(m, {m.sigmaA, m.sigmaS}, m.majorant, s, rng, beta, out)) return out;
    }
  }
  Vec3f og, dg;
  float s0, s1;
  if (!gridSegment(m, o, d, tMax, time01, og, dg, s0, s1)) return out;
  // Delta / spectral tracking, cell by cell: past a cell's end the next
  // distance is drawn afresh at the next cell's rate (memoryless).
  MajorantWalk walk(m, og, dg, s0, s1);
  float a, b, sb;
  while (walk.next(a, b, sb)) {
    if (!(sb > 0.0f)) continue;
    for (float s = a;;) {
      s += exponential(rng, sb);
      if (!(s < b)) break;
      if (collide(m, at(m, og, dg, s), sb, s, rng, beta, out)) return out;
    }
  }
  return out;
}

}  // namespace tdpm::media
