// image/tga.cpp — the TGA reader (see tga.h). The whole file is read into
// memory first (its size is bounded by what it claims to hold), then
// decoded with every read checked against the end.
#include "image/tga.h"

#include <cstdio>
#include <vector>

#include "core/error.h"
#include "image/image_limits.h"

namespace tdpm::image {

ImageRgb8 readTga(const std::string& path) {
  uint64_t size = 0;
  std::FILE* f = openRegularFile(path, size);
  auto fail = [&](const std::string& why) -> Error { return Error(path + ": " + why); };
  if (size < 18) {
    std::fclose(f);
    throw fail("not a TGA file (shorter than its 18-byte header)");
  }
  // At 1 byte per run of 128 pixels the file holds at most 128x its size
  // in pixels: refuse a header that claims more before reading anything.
  std::vector<unsigned char> data(static_cast<size_t>(size));
  size_t got = std::fread(data.data(), 1, data.size(), f);
  std::fclose(f);
  if (got != data.size()) throw fail("read error");
  const unsigned char* h = data.data();
  const int idLength = h[0], mapType = h[1], type = h[2];
  const int width = h[12] | (h[13] << 8), height = h[14] | (h[15] << 8);
  const int depth = h[16], descriptor = h[17];
  if (mapType != 0 || type == 1 || type == 9) throw fail("colour-mapped TGA files are not supported (truecolour or greyscale only)");
  if (type != 2 && type != 3 && type != 10 && type != 11)
    throw fail("TGA image type " + std::to_string(type) + " is not supported (2, 3, 10 or 11: truecolour or greyscale, raw or RLE)");
  const bool grey = type == 3 || type == 11, rle = type >= 10;
  if (grey ? depth != 8 : (depth != 24 && depth != 32))
    throw fail("TGA with " + std::to_string(depth) + " bits per pixel is not supported (" +
               (grey ? "8 for greyscale)" : "24 or 32 for truecolour)"));
  if (width <= 0 || height <= 0) throw fail("TGA image has no pixels (" + std::to_string(width) + " x " + std::to_string(height) + ")");
  if (uint64_t(width) * uint64_t(height) > 128 * size) throw fail("TGA image " + std::to_string(width) + "x" + std::to_string(height) + " cannot be held by a file of " + std::to_string(size) + " bytes");
  checkDecodedImageFits(path, "TGA", width, height, 3);
  const size_t bpp = size_t(depth / 8), count = size_t(width) * size_t(height);
  size_t at = 18 + size_t(idLength);
  std::vector<unsigned char> px(count * bpp);
  auto truncated = [&]() { return fail("TGA pixel data ends early (file truncated)"); };
  if (!rle) {
    if (at + px.size() > data.size()) throw truncated();
    std::copy(data.begin() + long(at), data.begin() + long(at + px.size()), px.begin());
  } else {
    size_t n = 0;
    while (n < count) {
      if (at >= data.size()) throw truncated();
      const unsigned char packet = data[at++];
      const size_t run = size_t(packet & 0x7f) + 1;
      if (n + run > count) throw fail("a TGA run-length packet passes the end of the image");
      if (packet & 0x80) {  // one pixel, repeated
        if (at + bpp > data.size()) throw truncated();
        for (size_t k = 0; k < run; ++k) std::copy(&data[at], &data[at] + bpp, &px[(n + k) * bpp]);
        at += bpp;
      } else {  // run raw pixels
        if (at + run * bpp > data.size()) throw truncated();
        std::copy(&data[at], &data[at] + run * bpp, &px[n * bpp]);
        at += run * bpp;
      }
      n += run;
    }
  }
  ImageRgb8 out;
  out.width = width;
  out.height = height;
  out.rgb.resize(count * 3);
  const bool topDown = (descriptor & 0x20) != 0, rightToLeft = (descriptor & 0x10) != 0;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const unsigned char* s = &px[(size_t(y) * size_t(width) + size_t(x)) * bpp];
      const int oy = topDown ? y : height - 1 - y, ox = rightToLeft ? width - 1 - x : x;
      unsigned char* d = &out.rgb[(size_t(oy) * size_t(width) + size_t(ox)) * 3];
      if (grey) d[0] = d[1] = d[2] = s[0];
      else d[0] = s[2], d[1] = s[1], d[2] = s[0];  // stored as BGR(A)
    }
  return out;
}

}  // namespace tdpm::image
