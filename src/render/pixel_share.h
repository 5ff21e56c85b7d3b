// render/pixel_share.h — per-pixel arrays of a distributed render put back
// together: each rank computed the pixels of the tiles its TileShare owns
// (render/tile_loop.h); these collect them, exactly (bytes are copied,
// nothing is added), on every rank or on rank 0 only.
#pragma once
#include <cstdint>
#include <type_traits>
#include <vector>

#include "dist/comm.h"
#include "render/tile_loop.h"

namespace tdpm {

inline TileShare tileShareOf(const dist::Comm& comm) { return TileShare{comm.rank(), comm.size()}; }

// `px` holds width x height values, row-major; on return the pixels of
// every rank's tiles hold that rank's values, on every rank
// (everyRank) or on rank 0 only. Pixels travel tile by tile, row by row.
template <class T>
void sharePixels(dist::Comm& comm, int width, int height, std::vector<T>& px, bool everyRank) {
  static_assert(std::is_trivially_copyable<T>::value, "pixels travel as bytes");
  if (!comm.distributed()) return;
  const int n = comm.size();
  std::vector<std::vector<size_t>> tiles(static_cast<size_t>(n));
  std::vector<uint64_t> bytes(static_cast<size_t>(n), 0);
  for (int r = 0; r < n; ++r) {
    tiles[size_t(r)] = ownedTiles(width, height, TileShare{r, n});
    for (size_t i : tiles[size_t(r)]) {
      Tile t = tileAt(i, width, height);
      bytes[size_t(r)] += uint64_t(t.x1 - t.x0) * uint64_t(t.y1 - t.y0) * sizeof(T);
    }
  }
  auto visit = [&](int r, auto&& f) {
    size_t k = 0;
    for (size_t i : tiles[size_t(r)]) {
      Tile t = tileAt(i, width, height);
      for (int y = t.y0; y < t.y1; ++y)
        for (int x = t.x0; x < t.x1; ++x) f(size_t(y) * size_t(width) + size_t(x), k++);
    }
  };
  std::vector<T> mine(size_t(bytes[size_t(comm.rank())] / sizeof(T)));
  visit(comm.rank(), [&](size_t p, size_t k) { mine[k] = px[p]; });
  std::vector<T> all(size_t(width) * size_t(height));
  if (everyRank) comm.allgatherv(mine.data(), all.data(), bytes);
  else comm.gathervToRoot(mine.data(), all.data(), bytes);
  if (!everyRank && !comm.root()) return;
  size_t offset = 0;
  for (int r = 0; r < n; ++r) {
    if (r != comm.rank()) visit(r, [&](size_t p, size_t k) { px[p] = all[offset + k]; });
    offset += size_t(bytes[size_t(r)] / sizeof(T));
  }
}

}  // namespace tdpm
