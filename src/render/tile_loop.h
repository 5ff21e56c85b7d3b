// render/tile_loop.h — the one parallel loop over image tiles (TBB).
// Every renderer goes through it: tiles of kTileSize^2 pixels are handed to
// worker threads; the per-tile function gets the tile's pixel rectangle and
// a per-thread scratch object it may reuse (no allocation per sample, no
// locks). Progress is reported once per finished tile. Results must depend
// only on the pixel (seeded per pixel), so they are identical for any
// thread count and any tile order. A distributed render (distributed/) either
// hands the tiles out as the ranks ask for them (forEachClaimedTile: a
// queue, which absorbs ranks running at different speeds) or gives each
// rank the tiles its TileShare owns (a fixed interleave).
//
// Tiles are handed out scattered over the image (or the rank's share), not
// row by row: tile number k is (k * stride) mod total with stride near
// 0.618 total and coprime to it (a permutation: a Weyl sequence). The tiles
// finished at any moment are then a fair sample of the image, so the
// progress bar's time left, measured from them, holds; in row order the
// cheap sky came first and the bar said "0:04 left" at 25% of a 29 s render
// (scenes/glass-ball.json, cli/progress_bar.h).
#pragma once
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "core/progress.h"

namespace tdpm {

struct Tile {
  int x0, y0, x1, y1;  // [x0, x1) x [y0, y1)
};

constexpr int kTileSize = 16;

// The stride of the scattered tile order (see above): coprime to `total`.
inline size_t tileOrderStride(size_t total) {
  if (total <= 2) return 1;
  size_t s = size_t(double(total) * 0.6180339887498949);
  auto gcd = [](size_t a, size_t b) {
    while (b) { size_t t = a % b; a = b; b = t; }
    return a;
  };
  while (gcd(s, total) != 1) ++s;
  return s;
}

// Which tiles one rank of a distributed render owns: tile (tx, ty) belongs
// to rank (tx + ty) mod size, diagonal stripes, so every rank gets tiles
// from every part of the image (a caustic or a bright window is shared) and
// the split is fixed in advance: no work queue, and every rank knows who
// renders each pixel. One process (size 1) owns every tile.
struct TileShare {
  int rank = 0, size = 1;
  bool owns(int tx, int ty) const { return (tx + ty) % size == rank; }
  bool ownsTileOf(int x, int y) const { return owns(x / kTileSize, y / kTileSize); }
};

// Tile indices (row-major over the tile grid) owned by `share`, ascending.
inline std::vector<size_t> ownedTiles(int width, int height, const TileShare& share) {
  const int tilesX = (width + kTileSize - 1) / kTileSize;
  const int tilesY = (height + kTileSize - 1) / kTileSize;
  std::vector<size_t> tiles;
  for (int ty = 0; ty < tilesY; ++ty)
    for (int tx = 0; tx < tilesX; ++tx)
      if (share.owns(tx, ty)) tiles.push_back(size_t(ty) * size_t(tilesX) + size_t(tx));
  return tiles;
}

inline Tile tileAt(size_t index, int width, int height) {
  const int tilesX = (width + kTileSize - 1) / kTileSize;
  int tx = int(index % size_t(tilesX)), ty = int(index / size_t(tilesX));
  return Tile{tx * kTileSize, ty * kTileSize, std::min(width, (tx + 1) * kTileSize), std::min(height, (ty + 1) * kTileSize)};
}

// The loop over a given list of tile indices (scattered order, above).
template <class Scratch, class TileFn>
void forEachListedTile(int width, int height, const std::vector<size_t>& tiles, const std::string& stage,
                       const Progress& progress, TileFn&& fn) {
  const size_t total = tiles.size();
  const size_t stride = tileOrderStride(total);
  std::atomic<size_t> done{0};
  tbb::enumerable_thread_specific<Scratch> scratch;
  progress(stage, 0, total);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, total, 1), [&](const tbb::blocked_range<size_t>& r) {
    Scratch& s = scratch.local();
    for (size_t k = r.begin(); k != r.end(); ++k) {
      const size_t i = size_t((uint64_t(k) * stride) % total);  // tiles <= 2^24: no overflow
      Tile t = tileAt(tiles[i], width, height);
      fn(t, s);
      progress(stage, done.fetch_add(1) + 1, total);
    }
  });
}

template <class Scratch, class TileFn>
void forEachTile(int width, int height, const std::string& stage, const Progress& progress, TileFn&& fn,
                 const TileShare& share = {}) {
  forEachListedTile<Scratch>(width, height, ownedTiles(width, height, share), stage, progress, fn);
}

// Tiles handed out as they are asked for (a work queue): every thread of
// every rank takes the next number k of a counter the ranks share
// (`claim()`, dist::SharedCounter::fetchAdd(1)) and renders tile k of the
// scattered order of the whole image, until k passes the last tile. A rank
// on a faster (or less busy) core takes more tiles. Which rank renders a
// tile changes nothing in its pixels (they depend on the pixel and the
// seed), only who holds them: returns the tiles this process rendered,
// ascending. Progress counts the tiles taken by the whole job.
template <class Scratch, class TileFn, class Claim>
std::vector<size_t> forEachClaimedTile(int width, int height, const std::string& stage, const Progress& progress,
                                       TileFn&& fn, Claim&& claim) {
  const size_t total = ownedTiles(width, height, TileShare{}).size();
  const size_t stride = tileOrderStride(total);
  tbb::enumerable_thread_specific<Scratch> scratch;
  tbb::enumerable_thread_specific<std::vector<size_t>> taken;
  progress(stage, 0, total);
  const int workers = std::max(1, tbb::this_task_arena::max_concurrency());
  tbb::parallel_for(0, workers, [&](int) {
    Scratch& s = scratch.local();
    std::vector<size_t>& mine = taken.local();
    for (;;) {
      const uint64_t k = claim();
      if (k >= total) break;
      const size_t i = size_t((k * stride) % total);
      fn(tileAt(i, width, height), s);
      mine.push_back(i);
      progress(stage, size_t(k) + 1, total);
    }
  });
  progress(stage, total, total);  // every tile taken (the other ranks may still be at their last)
  std::vector<size_t> all;
  for (const std::vector<size_t>& m : taken) all.insert(all.end(), m.begin(), m.end());
  std::sort(all.begin(), all.end());
  return all;
}

}  // namespace tdpm
