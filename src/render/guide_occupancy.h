// render/guide_occupancy.h — a bit per grid cell saying whether a point in
// the cell can have at least m of a fixed point set within radius r.
//
// Why: the caustic guide (render/caustic_guide.h) asks a k-NN query at
// every eye path's diffuse vertex, and most of those vertices (walls, most
// of the floor) have no guide photon near; the k-NN then walks the tree
// only to find nothing. A cleared bit answers "fewer than m points lie
// within r of p" exactly (the k-NN would return fewer than m), in a few
// instructions; a set bit only says "maybe" and the k-NN decides. So
// skipping on a cleared bit never changes a result.
//
// A cell's bit is set when at least m points lie within r of the cell's box
// (not only of its centre), with a margin for float rounding of the query's
// cell index and of the k-NN's distances.
//
// Layout: one 16-byte word per brick of 4x4x4 cells (its 64 bits and the
// count of set bits before it), so a query reads one cache line, and cells
// near each other in space are near each other in rank order (the caustic
// guide's cache is laid out by rank).
#pragma once
#include <cstdint>
#include <vector>

#include "math/vec.h"

namespace tdpm {

class GuideOccupancy {
 public:
  GuideOccupancy() = default;  // empty: mayHaveNear() is always true

  // Cells are r/2 wide (wider if the points' bounds grown by r would need
  // more than maxCells). The k-NN this stands for counts a point when its
  // squared distance is < r^2.
  static GuideOccupancy build(const std::vector<Vec3f>& points, float radius, int minCount,
                              size_t maxCells = size_t(1) << 24);

  // false: fewer than minCount points lie within the radius of p (exact).
  // true: maybe (or no grid was built).
  bool mayHaveNear(Vec3f p) const {
    if (!built_) return true;
    float fx = (p.x - lo_.x) * invCell_, fy = (p.y - lo_.y) * invCell_, fz = (p.z - lo_.z) * invCell_;
    // Outside the grid (which holds every point grown by the radius), or NaN.
    if (!(fx >= 0.0f && fy >= 0.0f && fz >= 0.0f && fx < float(nx_) && fy < float(ny_) && fz < float(nz_)))
      return false;
    const Word& w = words_[wordIndex(int(fx), int(fy), int(fz))];
    return (w.bits >> bitIndex(int(fx), int(fy), int(fz))) & 1u;
  }

  // For a cache keyed by set cells (render/caustic_guide.h): false as
  // mayHaveNear; else the rank of p's cell among the set cells (in cell
  // index order), p's place inside the cell, in [0, 1] per axis, and the
  // cell's lower corner (as setCellCorners gives it).
  bool locate(Vec3f p, size_t& rank, Vec3f& local, Vec3f* corner = nullptr) const {
    if (!built_) return false;
    float fx = (p.x - lo_.x) * invCell_, fy = (p.y - lo_.y) * invCell_, fz = (p.z - lo_.z) * invCell_;
    if (!(fx >= 0.0f && fy >= 0.0f && fz >= 0.0f && fx < float(nx_) && fy < float(ny_) && fz < float(nz_)))
      return false;
    int ix = int(fx), iy = int(fy), iz = int(fz);
    const Word& w = words_[wordIndex(ix, iy, iz)];
    unsigned bit = bitIndex(ix, iy, iz);
    if (!((w.bits >> bit) & 1u)) return false;
    rank = size_t(w.rank) + size_t(__builtin_popcountll(w.bits & ((uint64_t(1) << bit) - 1)));
    local = Vec3f(fx - float(ix), fy - float(iy), fz - float(iz));
    if (corner) *corner = cellCorner(ix, iy, iz);
    return true;
  }
  // The set cells' lower corners, in rank order.
  std::vector<Vec3f> setCellCorners() const;

  bool built() const { return built_; }
  float cellSize() const { return cell_; }
  size_t cellCount() const { return size_t(nx_) * size_t(ny_) * size_t(nz_); }
  size_t bytes() const { return words_.size() * sizeof(Word); }
  size_t setCount() const;  // cells whose bit is set (for stats and tests)

 private:
  void setBits(const std::vector<uint8_t>& count, int minCount);  // build: the bits from the counts
  Vec3f cellCorner(int x, int y, int z) const {
    return Vec3f(lo_.x + float(x) * cell_, lo_.y + float(y) * cell_, lo_.z + float(z) * cell_);
  }
  size_t cellIndex(int x, int y, int z) const { return (size_t(z) * size_t(ny_) + size_t(y)) * size_t(nx_) + size_t(x); }
  size_t wordIndex(int x, int y, int z) const {
    return (size_t(z >> 2) * size_t(by_) + size_t(y >> 2)) * size_t(bx_) + size_t(x >> 2);
  }
  static unsigned bitIndex(int x, int y, int z) { return unsigned(((z & 3) << 4) | ((y & 3) << 2) | (x & 3)); }

  bool built_ = false;
  Vec3f lo_;
  float cell_ = 0.0f, invCell_ = 0.0f;
  int nx_ = 0, ny_ = 0, nz_ = 0;
  int bx_ = 0, by_ = 0, bz_ = 0;  // bricks per axis
  struct alignas(16) Word {
    uint64_t bits;  // the brick's cells, bit (z%4)*16 + (y%4)*4 + x%4
    uint32_t rank;  // set bits in the words before this one
    uint32_t unused;
  };
  std::vector<Word> words_;
};

}  // namespace tdpm
