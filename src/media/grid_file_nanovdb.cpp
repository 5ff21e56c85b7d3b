// media/grid_file_nanovdb.cpp — a NanoVDB .nvdb file's float grid made
// dense (grid_readers.h), with libnanovdb-dev's header-only reader. That
// reader trusts the file: a name length or a grid size read from a
// damaged file is allocated as given. So the segment headers are walked
// and checked here first (sizes against the file, names short and
// terminated), and the grid read is validated (nanovdb::GridValidator:
// checksum and node pointers) before a voxel is looked up.
#include <cstring>
#include <fstream>
#include <iostream>  // nanovdb/util/GridValidator.h uses std::cerr without including it

#define NANOVDB_USE_ZIP 1     // zlib-compressed segments (pbrt-v4 writes these)
#define NANOVDB_USE_BLOSC 1   // blosc-compressed segments
#include <nanovdb/NanoVDB.h>
#include <nanovdb/util/GridValidator.h>
#include <nanovdb/util/IO.h>

#include "core/error.h"
#include "media/grid_readers.h"

namespace tdpm::media::detail {

namespace {

struct Entry {
  std::string name;
  nanovdb::GridType type;
  uint64_t gridSize;
};

// The grids a file holds, every size checked against the file's own size.
std::vector<Entry> listGrids(const std::string& pre, std::ifstream& is, uint64_t fileSize) {
  std::vector<Entry> out;
  uint64_t pos = 0;
  while (pos < fileSize) {
    nanovdb::io::Header h;
    if (fileSize - pos < sizeof h || !is.read(reinterpret_cast<char*>(&h), sizeof h))
      throw Error(pre + "truncated NanoVDB segment header at byte " + std::to_string(pos));
    pos += sizeof h;
    if (h.magic != NANOVDB_MAGIC_NUMBER) throw Error(pre + "not a NanoVDB file (bad magic number at byte " + std::to_string(pos - sizeof h) + ")");
    if (h.gridCount == 0) throw Error(pre + "a NanoVDB segment with no grids (damaged file?)");
    uint64_t data = 0;
    for (uint16_t k = 0; k < h.gridCount; ++k) {
      nanovdb::io::MetaData m;
      if (fileSize - pos < sizeof m || !is.read(reinterpret_cast<char*>(&m), sizeof m))
        throw Error(pre + "truncated NanoVDB grid header at byte " + std::to_string(pos));
      pos += sizeof m;
      if (m.nameSize == 0 || m.nameSize > 4096 || m.nameSize > fileSize - pos)
        throw Error(pre + "a NanoVDB grid name of " + std::to_string(m.nameSize) + " bytes (damaged file?)");
      std::string name(m.nameSize, '\0');
      if (!is.read(name.data(), m.nameSize) || name.back() != '\0') throw Error(pre + "a NanoVDB grid name is not terminated (damaged file?)");
      name.resize(std::strlen(name.c_str()));
      pos += m.nameSize;
      data += m.fileSize;
      // An uncompressed grid is stored as it is in memory; a compressed one
      // is allowed 1024 times its bytes on disk (far above zlib's or
      // blosc's ratio on density data).
      bool plain = h.codec == nanovdb::io::Codec::NONE;
      if (plain ? m.gridSize != m.fileSize : m.gridSize / 1024 > m.fileSize)
        throw Error(pre + "grid \"" + name + "\" claims " + std::to_string(m.gridSize) + " bytes in memory from " +
                    std::to_string(m.fileSize) + " in the file (damaged file?)");
      out.push_back({name, m.gridType, m.gridSize});
    }
    if (data > fileSize - pos) throw Error(pre + "the file is shorter than its NanoVDB grid sizes say (truncated?)");
    pos += data;
    is.seekg(std::streamoff(pos));
  }
  return out;
}

}  // namespace

void readNanoVdb(scene::DensityGridDesc& g, const std::string& where, uint64_t maxBytes, uint64_t fileSize) {
  const std::string pre = where + ": density grid file \"" + g.file + "\": ";
  std::ifstream is(g.file, std::ios::binary);
  if (!is) throw Error(pre + "cannot open it");
  std::vector<Entry> grids = listGrids(pre, is, fileSize);
  const Entry* e = nullptr;
  std::vector<std::string> names;
  for (const Entry& x : grids) {
    names.push_back(x.name);
    if (x.name == g.gridName && !e) e = &x;
  }
  if (!e) throw Error(pre + "has no grid named \"" + g.gridName + "\" (its grids: " + listNames(names) + ")");
  if (e->type != nanovdb::GridType::Float)
    throw Error(gridPrefix(g, where) + "is a " + nanovdb::toStr(e->type) + " grid; a density grid must hold floats");
  if (e->gridSize > maxBytes) throw Error(gridPrefix(g, where) + "its " + std::to_string(e->gridSize) + " bytes are more than the " + std::to_string(maxBytes) + " bytes allowed");
  nanovdb::GridHandle<nanovdb::HostBuffer> handle;
  try {
    is.clear();
    is.seekg(0);
    handle = nanovdb::io::readGrid<nanovdb::HostBuffer>(is, g.gridName);
  } catch (const std::bad_alloc&) {
    throw Error(pre + "out of memory while reading grid \"" + g.gridName + "\"");
  } catch (const std::exception& x) {
    throw Error(pre + "cannot read grid \"" + g.gridName + "\" (" + x.what() + ")");
  }
  const nanovdb::NanoGrid<float>* grid = handle.grid<float>();
  if (!grid) throw Error(gridPrefix(g, where) + "could not be read as a float grid (damaged file?)");
  std::string bad = nanovdb::GridValidator<float>::check(*grid, /*detailed=*/true);
  if (!bad.empty()) throw Error(gridPrefix(g, where) + "the grid is damaged (" + bad + ")");
  IndexBox box;
  const nanovdb::Map& map = grid->map();
  // nanovdb::Map stores the index-to-world 3x3 (column-vector form, mMatD[row][col]) and the translation.
  double m[4][4] = {};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m[c][r] = map.mMatD[r * 3 + c];
  for (int c = 0; c < 3; ++c) m[3][c] = map.mVecD[c];
  m[3][3] = 1;
  axisAlignedMap(g, where, m, &box);
  if (grid->activeVoxelCount() == 0) throw Error(gridPrefix(g, where) + "the grid is empty (no active voxels)");
  const nanovdb::CoordBBox& bb = grid->indexBBox();
  for (int a = 0; a < 3; ++a) {
    box.lo[a] = bb.min()[a];
    box.hi[a] = bb.max()[a];
  }
  sizeGrid(g, where, box, maxBytes);
  g.density.assign(size_t(g.nx) * size_t(g.ny) * size_t(g.nz), 0.0f);
  auto acc = grid->getAccessor();
  size_t i = 0;
  for (int z = 0; z < g.nz; ++z)
    for (int y = 0; y < g.ny; ++y)
      for (int x = 0; x < g.nx; ++x)
        g.density[i++] = acc.getValue(nanovdb::Coord(int(box.lo[0] + x), int(box.lo[1] + y), int(box.lo[2] + z)));
  checkDensities(g, where, box);
}

}  // namespace tdpm::media::detail
