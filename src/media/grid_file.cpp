// media/grid_file.cpp — density grids from files (see grid_file.h). Until a
// grid reader is built, every file is refused with a located error.
#include "media/grid_file.h"

#include "core/error.h"

namespace tdpm::media {

void loadDensityGridFile(scene::DensityGridDesc& grid, const std::string& where, uint64_t /*maxBytes*/) {
  throw Error(where + ": density grid file \"" + grid.file +
              "\": reading grid files is not supported in this build; give the density inline (\"resolution\" and \"density\")");
}

}  // namespace tdpm::media
