// media/grid_checks.cpp — the checks both grid file readers share
// (media/grid_readers.h): size before allocation, axis-aligned index-to-
// world map, densities non-negative and finite, the messages' wording.
// Compiled into tdpm_lib and into the OpenVDB reader module
// (libtdpm_openvdb.so, which has no tdpm_lib of its own).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/error.h"
#include "media/grid_readers.h"

namespace tdpm::media {

namespace detail {

namespace {
// Whatever maxBytes says, no dense grid above 4 GiB (a 1024^3 grid) is
// made: tdpm's grid lookups index it with 32-bit cell counts per axis and
// a grid that large is better kept sparse (not supported).
constexpr uint64_t kHardCapBytes = uint64_t(4) << 30;

std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}
}  // namespace

std::string gridPrefix(const scene::DensityGridDesc& g, const std::string& where) {
  return where + ": density grid file \"" + g.file + "\" grid \"" + g.gridName + "\": ";
}

std::string listNames(const std::vector<std::string>& names) {
  if (names.empty()) return "none";
  std::string s;
  for (size_t i = 0; i < names.size(); ++i) s += (i ? ", \"" : "\"") + names[i] + "\"";
  return s;
}

void sizeGrid(scene::DensityGridDesc& g, const std::string& where, const IndexBox& box, uint64_t maxBytes) {
  uint64_t n[3];
  for (int a = 0; a < 3; ++a) {
    if (box.hi[a] < box.lo[a]) throw Error(gridPrefix(g, where) + "the grid is empty (no active voxels)");
    n[a] = uint64_t(box.hi[a] - box.lo[a]) + 1;
  }
  const uint64_t cap = std::min(maxBytes, kHardCapBytes);
  // n[a] < 2^33 each (32-bit coordinates): the product in long double is exact enough to compare.
  long double bytes = (long double)n[0] * (long double)n[1] * (long double)n[2] * 4.0L;
  std::string dims = std::to_string(n[0]) + " x " + std::to_string(n[1]) + " x " + std::to_string(n[2]);
  if (bytes > (long double)cap || n[0] > (1u << 30) || n[1] > (1u << 30) || n[2] > (1u << 30)) {
    char b[64];
    std::snprintf(b, sizeof b, "%.0Lf", bytes);
    throw Error(gridPrefix(g, where) + "the active voxels span " + dims + " cells, " + b +
                " bytes as a dense grid, more than the " + std::to_string(cap) + " bytes allowed" +
                (cap == kHardCapBytes ? " (tdpm's limit for one dense grid)" : " (the memory limit)"));
  }
  g.nx = int(n[0]);
  g.ny = int(n[1]);
  g.nz = int(n[2]);
  Vec3f lo, hi;
  float* l = &lo.x;
  float* h = &hi.x;
  for (int a = 0; a < 3; ++a) {
    l[a] = float(box.origin[a] + box.scale[a] * (double(box.lo[a]) - 0.5));
    h[a] = float(box.origin[a] + box.scale[a] * (double(box.hi[a]) + 0.5));
    if (!std::isfinite(l[a]) || !std::isfinite(h[a]) || !(h[a] > l[a]))
      throw Error(gridPrefix(g, where) + "its world bounds are not finite or have no extent (voxel size " +
                  num(box.scale[a]) + ")");
  }
  g.bounds = Bounds3f{lo, hi};
}

void axisAlignedMap(const scene::DensityGridDesc& g, const std::string& where, const double m[4][4], IndexBox* box) {
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      if (!std::isfinite(m[r][c])) throw Error(gridPrefix(g, where) + "its index-to-world transform is not finite");
  if (m[0][3] != 0 || m[1][3] != 0 || m[2][3] != 0 || m[3][3] != 1)
    throw Error(gridPrefix(g, where) + "its index-to-world transform is projective (a frustum grid); not supported");
  for (int r = 0; r < 3; ++r) {
    double d = m[r][r];
    if (!(d > 0))
      throw Error(gridPrefix(g, where) + "its index-to-world transform " + (d < 0 ? "mirrors" : "collapses") +
                  " axis " + "xyz"[r] + " (voxel size " + num(d) + "); tdpm needs positive voxel sizes");
    for (int c = 0; c < 3; ++c)
      if (c != r && std::fabs(m[r][c]) > 1e-9 * d)
        throw Error(gridPrefix(g, where) +
                    "its index-to-world transform rotates or shears the voxels; tdpm reads axis-aligned grids only "
                    "(scale and translate): place the medium with its own transform instead");
    box->scale[r] = d;
    box->origin[r] = m[3][r];
  }
}

void checkDensities(const scene::DensityGridDesc& g, const std::string& where, const IndexBox& box) {
  const size_t nx = size_t(g.nx), ny = size_t(g.ny);
  for (size_t i = 0; i < g.density.size(); ++i) {
    float v = g.density[i];
    if (std::isfinite(v) && v >= 0) continue;
    int64_t x = box.lo[0] + int64_t(i % nx), y = box.lo[1] + int64_t((i / nx) % ny), z = box.lo[2] + int64_t(i / (nx * ny));
    throw Error(gridPrefix(g, where) + "voxel (" + std::to_string(x) + ", " + std::to_string(y) + ", " + std::to_string(z) +
                ") has density " + num(v) + "; densities must be finite and >= 0");
  }
}

}  // namespace detail

}  // namespace tdpm::media
