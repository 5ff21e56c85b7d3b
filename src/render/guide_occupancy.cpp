// render/guide_occupancy.cpp — building the occupancy bits.
#include "render/guide_occupancy.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tdpm {

// The bits (a cell with at least minCount points in reach) and the words'
// running ranks, from the per-cell counts of build().
void GuideOccupancy::setBits(const std::vector<uint8_t>& count, int minCount) {
  bx_ = (nx_ + 3) / 4;
  by_ = (ny_ + 3) / 4;
  bz_ = (nz_ + 3) / 4;
  words_.assign(size_t(bx_) * size_t(by_) * size_t(bz_), Word{0, 0, 0});
  for (int z = 0; z < nz_; ++z)
    for (int y = 0; y < ny_; ++y)
      for (int x = 0; x < nx_; ++x)
        if (count[cellIndex(x, y, z)] >= minCount) words_[wordIndex(x, y, z)].bits |= uint64_t(1) << bitIndex(x, y, z);
  uint32_t before = 0;
  for (Word& w : words_) {
    w.rank = before;
    before += uint32_t(__builtin_popcountll(w.bits));
  }
}

GuideOccupancy GuideOccupancy::build(const std::vector<Vec3f>& points, float radius, int minCount, size_t maxCells) {
  GuideOccupancy g;
  if (points.empty() || !(radius > 0.0f) || !std::isfinite(radius) || minCount < 1 || minCount > 255) return g;
  Vec3f lo(std::numeric_limits<float>::infinity()), hi(-std::numeric_limits<float>::infinity());
  for (Vec3f p : points) {
    if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))) return g;  // no grid: always "maybe"
    lo = vmin(lo, p);
    hi = vmax(hi, p);
  }
  double extent[3] = {double(hi.x) - lo.x, double(hi.y) - lo.y, double(hi.z) - lo.z};
  // The radius the cells are tested with: the k-NN's own float rounding of
  // |x_p - p|^2 (relative to the coordinates' size) and that of the query's
  // cell index (float (p - lo) / cell errs by up to ~3 ulps of an index
  // below 2^14, < 0.006 cells) must never clear a bit the exact test would
  // set, so the test radius is a little larger.
  double maxAbs = std::max({std::fabs(double(lo.x)), std::fabs(double(lo.y)), std::fabs(double(lo.z)),
                            std::fabs(double(hi.x)), std::fabs(double(hi.y)), std::fabs(double(hi.z))});
  auto testRadius = [&](double c) { return double(radius) * (1.0 + 1e-4) + 0.02 * c + 1e-5 * maxAbs; };
  // Not below 1e-4 of the coordinates, so that the rounding margin stays a
  // tenth of a cell and a point's test radius spans at most 7 cells.
  double cell = std::max(0.5 * double(radius), 1e-4 * maxAbs);
  long n[3];
  for (;;) {
    double grow = testRadius(cell) + cell;  // one spare cell each side
    double cells = 1.0;
    bool narrow = true;
    for (int a = 0; a < 3; ++a) {
      n[a] = long(std::ceil((extent[a] + 2.0 * grow) / cell));
      cells *= double(n[a]);
      narrow = narrow && n[a] <= (1L << 14);
    }
    if (cells <= double(maxCells) && narrow) break;
    cell *= 1.25;
  }
  double rt = testRadius(cell);
  double grow = rt + cell;
  double origin[3] = {double(lo.x) - grow, double(lo.y) - grow, double(lo.z) - grow};
  g.lo_ = Vec3f(float(origin[0]), float(origin[1]), float(origin[2]));
  // The query measures from the float origin: use it here too.
  for (int a = 0; a < 3; ++a) origin[a] = double(g.lo_[a]);
  g.cell_ = float(cell);
  g.invCell_ = float(1.0 / cell);
  g.nx_ = int(n[0]);
  g.ny_ = int(n[1]);
  g.nz_ = int(n[2]);

  std::vector<uint8_t> count(g.cellCount(), 0);
  const double rt2 = rt * rt;
  constexpr int kMaxSpan = 8;  // cells per axis within the test radius: <= 2 rt / cell + 2 < 7
  for (Vec3f p : points) {
    double q[3] = {p.x, p.y, p.z};
    long i0[3], span[3];
    double d2[3][kMaxSpan];  // per axis: squared distance from p to the cell's slab
    for (int a = 0; a < 3; ++a) {
      i0[a] = std::max(0L, long(std::floor((q[a] - rt - origin[a]) / cell)));
      long i1 = std::min(n[a] - 1, long(std::floor((q[a] + rt - origin[a]) / cell)));
      span[a] = std::min<long>(kMaxSpan, i1 - i0[a] + 1);
      for (long i = 0; i < span[a]; ++i) {
        double b0 = origin[a] + double(i0[a] + i) * cell, b1 = b0 + cell;
        double d = q[a] < b0 ? b0 - q[a] : (q[a] > b1 ? q[a] - b1 : 0.0);
        d2[a][i] = d * d;
      }
    }
    for (long z = 0; z < span[2]; ++z)
      for (long y = 0; y < span[1]; ++y) {
        double dyz = d2[2][z] + d2[1][y];
        if (dyz > rt2) continue;
        for (long x = 0; x < span[0]; ++x) {
          if (dyz + d2[0][x] > rt2) continue;
          uint8_t& c = count[g.cellIndex(int(i0[0] + x), int(i0[1] + y), int(i0[2] + z))];
          if (c < minCount) ++c;
        }
      }
  }
  g.setBits(count, minCount);
  g.built_ = true;
  return g;
}

size_t GuideOccupancy::setCount() const {
  size_t s = 0;
  for (const Word& w : words_) s += size_t(__builtin_popcountll(w.bits));
  return s;
}

std::vector<Vec3f> GuideOccupancy::setCellCorners() const {
  std::vector<Vec3f> corners;
  if (!built_) return corners;
  corners.reserve(setCount());
  // Rank order: word by word, bit by bit.
  for (int bz = 0; bz < bz_; ++bz)
    for (int by = 0; by < by_; ++by)
      for (int bx = 0; bx < bx_; ++bx) {
        uint64_t bits = words_[(size_t(bz) * size_t(by_) + size_t(by)) * size_t(bx_) + size_t(bx)].bits;
        for (; bits; bits &= bits - 1) {
          unsigned b = unsigned(__builtin_ctzll(bits));
          corners.push_back(cellCorner(4 * bx + int(b & 3), 4 * by + int((b >> 2) & 3), 4 * bz + int(b >> 4)));
        }
      }
  return corners;
}

}  // namespace tdpm
