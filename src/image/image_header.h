// image/image_header.h — an image's size from its header alone, for
// `tdpm compare`, which must refuse two images of different sizes before
// decoding either (a 389 KB PNG of 20000x20000 took 15 s and 6.3 GB to
// decode only to be told "image sizes differ").
#pragma once
#include <optional>
#include <string>

#include "image/read_image.h"

namespace tdpm::image {

struct ImageHeader {
  ImageFormat format = ImageFormat::Exr;
  int width = 0, height = 0;
  int channels = 0;  // as stored: 1 (grey), 2 (grey + alpha), 3 (RGB), 4 (RGBA); 0 when the header does not say simply
};

// detectImageFormat (which throws for a missing, non-regular or unknown
// file), then the header's size: EXR's dataWindow (first part), PNG's IHDR,
// PFM's and Radiance HDR's resolution lines. nullopt when the header is not
// well formed enough to tell: the full reader then gives the precise error.
std::optional<ImageHeader> readImageHeader(const std::string& path);

}  // namespace tdpm::image
