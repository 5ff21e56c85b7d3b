// image/exr_header_check.h — a byte-level sanity check of OpenEXR headers,
// run before OpenEXR sees a file. Owns no OpenEXR code.
//
// Why: OpenEXR 3.1's C++ reader trusts the header. It allocates an
// attribute's claimed byte count before reading it, reads typed attributes
// (box2i, chlist, preview, ...) without checking that they fill their
// declared size (so the stream drifts and later "sizes" are read from
// pixel data), and sizes offset tables from the data window and tile size.
// fuzz_exr found damaged files of a few hundred bytes that made it allocate
// 0.8-2 GB. This check walks the header(s) the way OpenEXR reads them and
// rejects any attribute whose content disagrees with its declared size, any
// size beyond the end of the file, and data windows or tilings too large
// for tdpm, so that OpenEXR only ever gets headers with bounded allocations.
#pragma once
#include <cstdint>
#include <cstdio>
#include <string>

namespace tdpm::image {

// Limits shared with the reader (image/exr.cpp).
constexpr int64_t kMaxExrPixels = int64_t(1) << 27;  // 16k x 8k
constexpr int64_t kMaxExrTiles = int64_t(1) << 20;   // per level-0 image

// Walks the header(s) of the open EXR file `f` from its start (the caller
// has checked the magic number; the position is left anywhere). Returns ""
// if they are well formed, else a short description of the first problem,
// e.g. "attribute 'dataWindow' (box2i) declares 7 bytes; its type has 16".
std::string checkExrHeader(std::FILE* f);

}  // namespace tdpm::image
