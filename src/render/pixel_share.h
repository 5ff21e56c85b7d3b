// render/pixel_share.h — per-pixel arrays of a distributed render put back
// together: each rank computed the pixels of its tiles (taken from the tile
// queue, or owned by its TileShare: render/tile_loop.h); these collect them, exactly (bytes are copied,
// nothing is added), on every rank or on rank 0 only.
#pragma once
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "distributed/comm.h"
#include "render/tile_loop.h"

namespace tdpm {

inline TileShare tileShareOf(const dist::Comm& comm) { return TileShare{comm.rank(), comm.size()}; }

// Which tiles each rank rendered: tiles[r] = rank r's tile indices,
// ascending. Every rank holds the same lists.
struct TileOwners {
  std::vector<std::vector<size_t>> tiles;
  bool empty() const { return tiles.empty(); }
};

// The fixed interleave of TileShare, for every rank.
inline TileOwners staticTileOwners(int width, int height, int ranks) {
  TileOwners o;
  for (int r = 0; r < ranks; ++r) o.tiles.push_back(ownedTiles(width, height, TileShare{r, ranks}));
  return o;
}

// Collective: every rank's `mine` (the tiles it rendered, e.g. from
// forEachClaimedTile) on every rank. 4 bytes a tile.
inline TileOwners shareTileOwners(dist::Comm& comm, const std::vector<size_t>& mine) {
  std::vector<uint32_t> own(mine.begin(), mine.end());
  std::vector<uint64_t> counts = comm.allgather(uint64_t(own.size()));
  std::vector<uint64_t> bytes(counts.size());
  uint64_t total = 0;
  for (size_t r = 0; r < counts.size(); ++r) total += counts[r];
  for (size_t r = 0; r < counts.size(); ++r) bytes[r] = counts[r] * sizeof(uint32_t);
  std::vector<uint32_t> all(static_cast<size_t>(total));
  comm.allgatherv(own.data(), all.data(), bytes);
  TileOwners o;
  size_t offset = 0;
  for (size_t r = 0; r < counts.size(); ++r) {
    o.tiles.emplace_back(all.begin() + std::ptrdiff_t(offset), all.begin() + std::ptrdiff_t(offset + counts[r]));
    offset += size_t(counts[r]);
  }
  return o;
}

// `px` holds width x height values, row-major; on return the pixels of
// every rank's tiles (`owners`) hold that rank's values, on every rank
// (everyRank) or on rank 0 only. Pixels travel tile by tile, row by row.
template <class T>
void sharePixels(dist::Comm& comm, int width, int height, std::vector<T>& px, bool everyRank, const TileOwners& owners) {
  static_assert(std::is_trivially_copyable<T>::value, "pixels travel as bytes");
  if (!comm.distributed()) return;
  const int n = comm.size();
  const std::vector<std::vector<size_t>>& tiles = owners.tiles;
  std::vector<uint64_t> bytes(static_cast<size_t>(n), 0);
  for (int r = 0; r < n; ++r) {
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

// The same for the fixed interleave (TileShare) of every rank.
template <class T>
void sharePixels(dist::Comm& comm, int width, int height, std::vector<T>& px, bool everyRank) {
  if (!comm.distributed()) return;
  sharePixels(comm, width, height, px, everyRank, staticTileOwners(width, height, comm.size()));
}

}  // namespace tdpm
