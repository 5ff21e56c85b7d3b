// image/tga.h — Truevision TGA (Targa) reading for image textures: pbrt
// scenes ship .tga maps, and no Debian library the project already links
// reads them. Owns readTga.
#pragma once
#include <string>

#include "image/png.h"

namespace tdpm::image {

// Reads an uncompressed (type 2) or run-length encoded (type 10) truecolour
// TGA of 24 or 32 bits per pixel, or a greyscale one (types 3 and 11, 8
// bits), as 8-bit RGB codes, row 0 at the top (the descriptor's origin
// bits are honoured; alpha is dropped). Colour-mapped files are refused.
// Each side at most kMaxImageSide; a run or a row that passes the end of
// the file is an error. Throws tdpm::Error "<path>: <reason>".
ImageRgb8 readTga(const std::string& path);

}  // namespace tdpm::image
