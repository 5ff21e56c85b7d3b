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
// size beyond the end of the file, data windows over 65536 per side (the
// largest tdpm writes) or tilings too large for tdpm, and data windows whose
// pixels could not come out of a file this small even at the compression's
// best ratio (exrMaxCompressionRatio), so that OpenEXR and our reader only
// ever allocate in proportion to the file's real size.
#pragma once
#include <cstdint>
#include <cstdio>
#include <string>

namespace tdpm::image {

// Limits shared with the reader (image/exr.cpp). Per side: image_limits.h.
constexpr int64_t kMaxExrTiles = int64_t(1) << 20;  // per level-0 image

// The most decoded pixel bytes one byte of an OpenEXR file can hold with
// compression `code` (OpenEXR 3.1's numbering, 0 = NONE .. 9 = DWAB), from
// each codec's format: RLE 64 (a 2-byte run of 128); ZIP/ZIPS 1032
// (deflate's limit); PIZ 1032 (its Huffman run codes give ~410, bounded by
// deflate's for safety); PXR24 1376 (floats cut to 3 bytes, then deflate);
// B44/B44A 11 (a flat 4x4 block of halves in 3 bytes); DWAA/DWAB 66048 (a
// run-length pass, 64, then deflate). 0 for an unknown code.
uint64_t exrMaxCompressionRatio(int code);

// Walks the header(s) of the open EXR file `f` from its start (the caller
// has checked the magic number; the position is left anywhere). Returns ""
// if they are well formed, else a short description of the first problem,
// e.g. "attribute 'dataWindow' (box2i) declares 7 bytes; its type has 16".
std::string checkExrHeader(std::FILE* f);

}  // namespace tdpm::image
