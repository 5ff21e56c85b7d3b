// image/read_image.h — reads a picture in any format a reference comes in
// (OpenEXR, PFM, Radiance HDR, PNG) as linear RGB: what `tdpm compare`
// reads. Owns format detection; each format's reader owns its format.
#pragma once
#include <string>

#include "image/image.h"

namespace tdpm::image {

enum class ImageFormat { Exr, Pfm, Hdr, Png };

// "OpenEXR", "PFM", "Radiance HDR", "PNG".
const char* formatName(ImageFormat format);

// The format by the file's first bytes (the content decides; the extension
// only words the error). Throws tdpm::Error "<path>: <reason>" for a
// missing, unreadable or non-regular file, for content none of the four
// formats starts with, and when a known extension (.exr, .pfm, .hdr, .pic,
// .png, any case) names another format than the content has, so that a
// mislabelled file is noticed rather than read as something else.
ImageFormat detectImageFormat(const std::string& path);

struct LoadedImage {
  ImageRgb color;  // linear, row 0 at the top
  ImageFormat format = ImageFormat::Exr;
};

// detectImageFormat, then that format's reader (readExr's colour, readPfm,
// readHdr, readPngLinear). Only tdpm::Error "<path>: <reason>" leaves it.
LoadedImage readImage(const std::string& path);

}  // namespace tdpm::image
