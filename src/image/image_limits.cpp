// image/image_limits.cpp — memory check and regular-file opening shared by
// the image readers (see image_limits.h).
#include "image/image_limits.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>

#include "core/error.h"
#include "core/memory.h"

namespace tdpm::image {

namespace {
std::string megabytes(uint64_t bytes) { return std::to_string((bytes + (1u << 20) - 1) >> 20) + " MB"; }
}  // namespace

void checkDecodedImageFits(const std::string& path, const char* format, int64_t width, int64_t height,
                           uint64_t bytesPerPixel) {
  const uint64_t available = availableMemoryBytes();
  if (available == 0) return;
  // The same margin as the photon budget check: 256 MB plus 1/16 of what is
  // available, for the other image, OpenEXR's buffers and the system.
  const uint64_t margin = (uint64_t(256) << 20) + available / 16;
  const uint64_t usable = available > margin ? available - margin : 0;
  const uint64_t needed = uint64_t(width) * uint64_t(height) * bytesPerPixel;
  if (needed > usable)
    throw Error(path + ": " + format + " image " + std::to_string(width) + "x" + std::to_string(height) +
                " needs about " + megabytes(needed) + " of memory to read, but only " + megabytes(usable) +
                " is available (MemAvailable " + megabytes(available) + " less a margin)");
}

std::FILE* openRegularFile(const std::string& path, uint64_t& size) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) {
    int err = errno;
    throw Error(path + ": " + std::strerror(err));
  }
  if (S_ISDIR(st.st_mode)) throw Error(path + ": is a directory, not an image file");
  if (!S_ISREG(st.st_mode)) throw Error(path + ": is not a regular file (a device, FIFO or socket), not an image file");
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) {
    int err = errno;
    throw Error(path + ": " + std::strerror(err));
  }
  size = uint64_t(st.st_size);
  return f;
}

}  // namespace tdpm::image
