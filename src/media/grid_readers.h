// media/grid_readers.h — internal to media/grid_*.cpp: the two file
// readers (OpenVDB in grid_file_openvdb.cpp, a module opened on first use;
// NanoVDB in grid_file_nanovdb.cpp; the only files that include those
// libraries' slow headers) and the checks they share (grid_checks.cpp), so
// that both formats refuse the same things with the same words.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "scene/description.h"

namespace tdpm::media::detail {

// A grid's voxels as the readers find them: the active voxels' index box
// [lo, hi] (inclusive) and the index-to-world map, which must be axis
// aligned (world = origin + scale * index per axis, scale > 0).
struct IndexBox {
  int64_t lo[3] = {0, 0, 0}, hi[3] = {-1, -1, -1};
  double scale[3] = {1, 1, 1}, origin[3] = {0, 0, 0};
};

// "<where>: density grid file \"<file>\" grid \"<name>\": " — every message starts so.
std::string gridPrefix(const scene::DensityGridDesc& g, const std::string& where);

// Checks the index box (not empty) and the dense size against maxBytes
// and the hard cap before anything is allocated; sets nx, ny, nz and the
// world bounds (the box the cells tile: voxel centres are the integer
// index points, so the box reaches half a voxel past the outer centres).
void sizeGrid(scene::DensityGridDesc& g, const std::string& where, const IndexBox& box, uint64_t maxBytes);

// Refuses an index-to-world map that rotates, shears or mirrors; `m` is
// the 4x4 affine map in row-vector form (world = [i j k 1] * m), as both
// libraries store it.
void axisAlignedMap(const scene::DensityGridDesc& g, const std::string& where, const double m[4][4], IndexBox* box);

// The first negative or non-finite density (after the reader filled
// g.density) is a located error naming the voxel's index.
void checkDensities(const scene::DensityGridDesc& g, const std::string& where, const IndexBox& box);

// "a", "b" and "c" for messages listing the grids a file holds.
std::string listNames(const std::vector<std::string>& names);

void readNanoVdb(scene::DensityGridDesc& g, const std::string& where, uint64_t maxBytes, uint64_t fileSize);

}  // namespace tdpm::media::detail

namespace tdpm::media {
// The OpenVDB reader module's one entry (libtdpm_openvdb.so, exported as
// "tdpm_read_openvdb"): fills *grid as loadDensityGridFile does, or sets
// *error to the located message. Nothing is thrown across it.
using ReadOpenVdbFn = void (*)(scene::DensityGridDesc* grid, const std::string* where, uint64_t maxBytes, std::string* error);
}  // namespace tdpm::media
