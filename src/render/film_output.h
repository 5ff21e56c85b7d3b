// render/film_output.h — a Film as the EXR file tdpm writes: colour, the
// "spp" layer (samples taken per pixel) and "variance.R/G/B" (variance of
// each pixel's mean). Metadata is the caller's.
#pragma once
#include "image/exr.h"
#include "render/film.h"

namespace tdpm {

image::ExrFile filmToExr(const Film& film);

}  // namespace tdpm
