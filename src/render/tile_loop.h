// render/tile_loop.h — the one parallel loop over image tiles (TBB).
// Every renderer goes through it: tiles of kTileSize^2 pixels are handed to
// worker threads; the per-tile function gets the tile's pixel rectangle and
// a per-thread scratch object it may reuse (no allocation per sample, no
// locks). Progress is reported once per finished tile. Results must depend
// only on the pixel (seeded per pixel), so they are identical for any
// thread count.
#pragma once
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <string>

#include "core/progress.h"

namespace tdpm {

struct Tile {
  int x0, y0, x1, y1;  // [x0, x1) x [y0, y1)
};

constexpr int kTileSize = 16;

template <class Scratch, class TileFn>
void forEachTile(int width, int height, const std::string& stage, const Progress& progress, TileFn&& fn) {
  const int tilesX = (width + kTileSize - 1) / kTileSize;
  const int tilesY = (height + kTileSize - 1) / kTileSize;
  const size_t total = size_t(tilesX) * size_t(tilesY);
  std::atomic<size_t> done{0};
  tbb::enumerable_thread_specific<Scratch> scratch;
  progress(stage, 0, total);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, total, 1), [&](const tbb::blocked_range<size_t>& r) {
    Scratch& s = scratch.local();
    for (size_t i = r.begin(); i != r.end(); ++i) {
      int tx = int(i % size_t(tilesX)), ty = int(i / size_t(tilesX));
      Tile t{tx * kTileSize, ty * kTileSize, std::min(width, (tx + 1) * kTileSize), std::min(height, (ty + 1) * kTileSize)};
      fn(t, s);
      progress(stage, done.fetch_add(1) + 1, total);
    }
  });
}

}  // namespace tdpm
