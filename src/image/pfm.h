// image/pfm.h — Portable Float Map (PFM) files: pbrt's default output and a
// common reference format. Owns readPfm and writePfm.
//
// Format: "PF" (RGB) or "Pf" (grey), whitespace, width, whitespace, height,
// whitespace, a scale, exactly one whitespace character, then width *
// height * channels 32-bit floats, rows stored bottom to top; a negative
// scale means little-endian data, a positive one big-endian. Like pbrt-v4's
// reader, values are multiplied by |scale| when it is not 1.
// No Debian package reads PFM on its own (netpbm's library does not; stb
// does not; OpenImageIO and FreeImage would be large new dependencies for
// 60 lines), hence this small strict reader.
#pragma once
#include <string>

#include "image/image.h"

namespace tdpm::image {

// Reads a PFM file into linear RGB (grey: R = G = B), row 0 at the top.
// The data must be exactly width * height * channels * 4 bytes after the
// header (checked against the file's size before anything is allocated),
// each side at most 65536. Throws tdpm::Error "<path>: <reason>".
ImageRgb readPfm(const std::string& path);

// Writes `image` as a little-endian colour PFM ("PF", scale -1), rows
// bottom to top as the format wants. Atomic; throws tdpm::Error.
void writePfm(const std::string& path, const ImageRgb& image);

}  // namespace tdpm::image
