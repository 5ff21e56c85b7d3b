// image/image_limits.h — the size limits every image reader shares, and the
// memory check a reader runs before it allocates the decoded image.
// Owns: kMaxImageSide, checkDecodedImageFits, openRegularFile.
//
// Why these numbers: `tdpm render` writes images up to 65536 pixels per side
// (--resolution and the scene's "resolution" both stop there), so every
// reader admits that much; what a file may make us allocate is bounded by
// its real size (each reader's own check) and by the memory the machine has
// (here), so a valid but huge file is an error naming the bytes needed, not
// an out-of-memory kill.
#pragma once
#include <cstdint>
#include <cstdio>
#include <string>

namespace tdpm::image {

constexpr int64_t kMaxImageSide = 65536;

// Throws tdpm::Error "<path>: <format> image WxH needs about N MB to read,
// but only M MB of memory is available" when width * height *
// bytesPerPixel (what the reader is about to allocate) exceeds
// MemAvailable less a margin. Nothing is checked when MemAvailable cannot
// be read.
void checkDecodedImageFits(const std::string& path, const char* format, int64_t width, int64_t height,
                           uint64_t bytesPerPixel);

// Opens `path` for reading: it must exist and be a regular file (not a
// directory, a FIFO or /dev/zero). Returns the open file and its size in
// bytes; throws tdpm::Error "<path>: <reason>".
std::FILE* openRegularFile(const std::string& path, uint64_t& size);

}  // namespace tdpm::image
