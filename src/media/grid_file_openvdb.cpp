// media/grid_file_openvdb.cpp — an OpenVDB .vdb file's float grid made
// dense (grid_readers.h). The only file that includes OpenVDB (its headers
// are slow to compile and bring Boost); built, with grid_checks.cpp, as the
// module libtdpm_openvdb.so that grid_file.cpp opens the first time a .vdb
// is read (libopenvdb's start-up costs 0.1 s, see there).
#include <mutex>

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include "core/error.h"
#include "media/grid_readers.h"

namespace tdpm::media::detail {

namespace {

// The size of the grid's active voxels, known before its tree is read
// when the writer stored OpenVDB's usual "file_bbox_min/max" metadata.
bool fileBox(const openvdb::GridBase& meta, IndexBox* box) {
  openvdb::Metadata::ConstPtr lo = meta["file_bbox_min"], hi = meta["file_bbox_max"];
  auto l = openvdb::DynamicPtrCast<const openvdb::Vec3IMetadata>(lo);
  auto h = openvdb::DynamicPtrCast<const openvdb::Vec3IMetadata>(hi);
  if (!l || !h) return false;
  for (int a = 0; a < 3; ++a) {
    box->lo[a] = l->value()[a];
    box->hi[a] = h->value()[a];
  }
  return true;
}

void mapOf(const openvdb::GridBase& grid, const scene::DensityGridDesc& g, const std::string& where, IndexBox* box) {
  const openvdb::math::Transform& t = grid.transform();
  if (!t.isLinear()) throw Error(gridPrefix(g, where) + "its transform is not linear (a frustum grid); not supported");
  openvdb::math::Mat4d m = t.baseMap()->getAffineMap()->getMat4();
  double a[4][4];
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) a[r][c] = m(r, c);
  axisAlignedMap(g, where, a, box);
}

}  // namespace

namespace {
void readOpenVdb(scene::DensityGridDesc& g, const std::string& where, uint64_t maxBytes) {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
  const std::string pre = where + ": density grid file \"" + g.file + "\": ";
  openvdb::io::File file(g.file);
  try {
    file.open(/*delayLoad=*/false);
  } catch (const std::exception& e) {
    throw Error(pre + "not a readable OpenVDB file (" + e.what() + ")");
  }
  try {
    std::vector<std::string> names;
    for (auto it = file.beginName(); it != file.endName(); ++it) names.push_back(it.gridName());
    if (!file.hasGrid(g.gridName))
      throw Error(pre + "has no grid named \"" + g.gridName + "\" (its grids: " + listNames(names) + ")");
    openvdb::GridBase::Ptr meta = file.readGridMetadata(g.gridName);
    if (!meta->isType<openvdb::FloatGrid>())
      throw Error(gridPrefix(g, where) + "is a " + meta->valueType() + " grid; a density grid must hold floats");
    IndexBox box;
    mapOf(*meta, g, where, &box);
    // Sized before the tree is read when the file says its box (OpenVDB
    // writes it by default), and again from the tree itself.
    if (fileBox(*meta, &box)) sizeGrid(g, where, box, maxBytes);
    openvdb::FloatGrid::Ptr grid = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid(g.gridName));
    file.close();
    if (!grid) throw Error(gridPrefix(g, where) + "could not be read as a float grid");
    openvdb::CoordBBox bb = grid->evalActiveVoxelBoundingBox();
    if (grid->activeVoxelCount() == 0 || bb.empty()) throw Error(gridPrefix(g, where) + "the grid is empty (no active voxels)");
    for (int a = 0; a < 3; ++a) {
      box.lo[a] = bb.min()[a];
      box.hi[a] = bb.max()[a];
    }
    sizeGrid(g, where, box, maxBytes);
    g.density.assign(size_t(g.nx) * size_t(g.ny) * size_t(g.nz), 0.0f);
    // Every voxel in the box, active or not, as OpenVDB's samplers read it
    // (an inactive voxel holds the background or its own inactive value).
    openvdb::FloatGrid::ConstAccessor acc = grid->getConstAccessor();
    size_t i = 0;
    for (int z = 0; z < g.nz; ++z)
      for (int y = 0; y < g.ny; ++y)
        for (int x = 0; x < g.nx; ++x)
          g.density[i++] = acc.getValue(openvdb::Coord(int(box.lo[0] + x), int(box.lo[1] + y), int(box.lo[2] + z)));
    checkDensities(g, where, box);
  } catch (const Error&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw Error(pre + "out of memory while reading grid \"" + g.gridName + "\"");
  } catch (const std::exception& e) {
    throw Error(pre + "cannot read grid \"" + g.gridName + "\" (" + e.what() + ")");
  }
}

}  // namespace
}  // namespace tdpm::media::detail

// The module's entry (ReadOpenVdbFn): every refusal as text.
extern "C" __attribute__((visibility("default"))) void tdpm_read_openvdb(tdpm::scene::DensityGridDesc* grid,
                                                                         const std::string* where, uint64_t maxBytes,
                                                                         std::string* error) {
  static_assert(std::is_same_v<decltype(&tdpm_read_openvdb), tdpm::media::ReadOpenVdbFn>);
  try {
    tdpm::media::detail::readOpenVdb(*grid, *where, maxBytes);
  } catch (const std::exception& e) {
    *error = e.what();
  } catch (...) {
    *error = *where + ": density grid file \"" + grid->file + "\": unexpected failure in the OpenVDB reader";
  }
}
