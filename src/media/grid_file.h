// media/grid_file.h — reading a medium's density grid from a file (OpenVDB
// .vdb, NanoVDB .nvdb) into the flat, dense DensityGridDesc that the scene
// description holds. The one place that knows the grid file formats; the
// JSON parser and the pbrt importer both call it.
#pragma once
#include <cstdint>
#include <string>

#include "scene/description.h"

namespace tdpm::media {

// Fills grid.nx/ny/nz, grid.density and grid.bounds from grid.file (already
// resolved against the scene's folder), reading the grid named
// grid.gridName. `where` locates the statement for errors ("scene.json:
// media.smoke"). maxBytes: the dense grid's size is checked against it
// before anything is allocated. Throws tdpm::Error naming the file and the
// problem (missing, unreadable, no such grid, not a float grid, too large,
// negative or non-finite densities).
void loadDensityGridFile(scene::DensityGridDesc& grid, const std::string& where, uint64_t maxBytes);

}  // namespace tdpm::media
