// render/film_output.h — a Film as the files tdpm writes: the EXR (colour,
// the "spp" layer of samples taken per pixel and "variance.R/G/B", the
// variance of each pixel's mean) and its PNG preview, committed as a pair.
// Metadata is the caller's.
#pragma once
#include <string>

#include "image/exr.h"
#include "render/film.h"

namespace tdpm {

image::ExrFile filmToExr(const Film& film);
// The same without copying: colour and samples are moved out of `film`,
// and its interleaved variance is freed once split into the three layers.
image::ExrFile filmToExr(Film&& film);

// Writes the EXR at `exrPath` and the PNG preview (exposure in stops) at
// `pngPath` as one: both are written to temporaries in full, then both
// renamed into place (core/atomic_file commitTogether). On any failure
// (disk full, a directory in the way, a signal) both old files are left as
// they were and no temporary remains. Throws tdpm::Error naming the file.
void writeRenderOutputs(const std::string& exrPath, const std::string& pngPath, const image::ExrFile& exr,
                        float exposureStops);
// Its peak memory per pixel is render/memory_budget.h kWriteBytesPerPixel.

}  // namespace tdpm
