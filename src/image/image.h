// image/image.h — ImageRgb: the in-memory picture every image file format,
// metric and preview works on. Row-major, y down (row 0 = top row), linear
// radiometric floats; the same convention as EXR's INCREASING_Y scanlines and
// PNG rows, so no reader or writer ever flips.
#pragma once
#include <cstddef>
#include <vector>

#include "core/error.h"
#include "math/vec.h"

namespace tdpm::image {

struct ImageRgb {
  int width = 0, height = 0;
  std::vector<Rgb> pixels;  // width * height, index y * width + x

  ImageRgb() = default;
  ImageRgb(int w, int h, Rgb fill = Rgb()) : width(w), height(h) {
    TDPM_ASSERT(w >= 0 && h >= 0, "negative image size");
    pixels.assign(size_t(w) * size_t(h), fill);
  }

  size_t pixelCount() const { return size_t(width) * size_t(height); }
  bool empty() const { return width <= 0 || height <= 0; }
  bool inside(int x, int y) const { return x >= 0 && y >= 0 && x < width && y < height; }

  Rgb& at(int x, int y) { return pixels[size_t(y) * size_t(width) + size_t(x)]; }
  const Rgb& at(int x, int y) const { return pixels[size_t(y) * size_t(width) + size_t(x)]; }
};

}  // namespace tdpm::image
