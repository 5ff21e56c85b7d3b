// image/png.cpp — tone mapping to sRGB 8-bit and PNG I/O through libpng's
// simplified API (png_image), which reports errors in a message field
// instead of longjmp, so no setjmp is needed around C++ objects.
#include "image/png.h"

#include <png.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <vector>

#include "core/atomic_file.h"
#include "image/image_limits.h"

namespace tdpm::image {

float srgbEncode(float v) {
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

uint8_t toSrgb8(float linear) {
  // `!(x > 0)` also catches NaN, which would otherwise become UB in the cast.
  if (!(linear > 0.0f)) return 0;
  if (linear >= 1.0f) return 255;
  float e = srgbEncode(linear) * 255.0f + 0.5f;
  return uint8_t(std::min(e, 255.0f));
}

ImageRgb8 toPreview(const ImageRgb& image, float exposureStops) {
  const float scale = std::exp2(exposureStops);
  ImageRgb8 out;
  out.width = image.width;
  out.height = image.height;
  out.rgb.resize(image.pixelCount() * 3);
  for (size_t i = 0; i < image.pixelCount(); ++i)
    for (int c = 0; c < 3; ++c) out.rgb[3 * i + c] = toSrgb8(image.pixels[i][c] * scale);
  return out;
}

void writePngPreview(const std::string& path, const ImageRgb& image, float exposureStops) {
  AtomicFile out(path);
  writePngPreviewTo(out.tempPath(), path, image, exposureStops);
  out.commit();
}

void writePngPreviewTo(const std::string& tempPath, const std::string& path, const ImageRgb& image,
                       float exposureStops) {
  TDPM_ASSERT(!image.empty(), "writePngPreview: empty image");
  TDPM_ASSERT(image.pixels.size() == image.pixelCount(), "writePngPreview: pixel count does not match size");
  ImageRgb8 pixels = toPreview(image, exposureStops);

  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = png_uint_32(image.width);
  png.height = png_uint_32(image.height);
  png.format = PNG_FORMAT_RGB;  // 8-bit, non-linear: libpng adds an sRGB chunk
  if (!png_image_write_to_file(&png, tempPath.c_str(), 0, pixels.rgb.data(), 0, nullptr)) {
    std::string why = png.message;
    png_image_free(&png);
    throw Error(path + ": cannot write PNG: " + why);
  }
}

ImageRgb8 readPng(const std::string& path) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str())) {
    std::string why = png.message;
    png_image_free(&png);
    throw Error(path + ": cannot read PNG: " + why);
  }
  png.format = PNG_FORMAT_RGB;  // any PNG (grey, palette, 16-bit, alpha) -> 8-bit RGB
  ImageRgb8 out;
  out.width = int(png.width);
  out.height = int(png.height);
  try {
    out.rgb.resize(PNG_IMAGE_SIZE(png));
  } catch (...) {
    png_image_free(&png);  // the reader still holds the open file
    throw Error(path + ": PNG too large (" + std::to_string(png.width) + "x" + std::to_string(png.height) + ")");
  }
  if (!png_image_finish_read(&png, nullptr, out.rgb.data(), 0, nullptr)) {
    std::string why = png.message;
    png_image_free(&png);
    throw Error(path + ": cannot read PNG: " + why);
  }
  return out;
}

float srgbDecode(float v) {
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

ImageRgb readPngLinear(const std::string& path) {
  uint64_t fileSize = 0;
  std::FILE* f = openRegularFile(path, fileSize);  // regular files only: png_image_begin_read would read /dev/zero
  std::fclose(f);
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str())) {
    std::string why = png.message;
    png_image_free(&png);
    throw Error(path + ": cannot read PNG: " + why);
  }
  const int64_t w = png.width, h = png.height;
  // 1 bit per pixel compressed at most 1032:1 by deflate: the pixels the
  // file can hold, before anything is allocated for them.
  const bool tooWide = w > kMaxImageSide || h > kMaxImageSide;
  const bool tooMany = uint64_t(w) * uint64_t(h) / (8 * 1032) > fileSize;
  if (tooWide || tooMany) {
    png_image_free(&png);
    throw Error(path + ": PNG image " + std::to_string(w) + "x" + std::to_string(h) +
                (tooWide ? " is larger than " + std::to_string(kMaxImageSide) + " pixels per side"
                         : " cannot be held by a file of " + std::to_string(fileSize) + " bytes"));
  }
  const bool sixteen = (png.format & PNG_FORMAT_FLAG_LINEAR) != 0;
  try {
    checkDecodedImageFits(path, "PNG", w, h, sizeof(Rgb) + (sixteen ? 6 : 4));
  } catch (...) {
    png_image_free(&png);
    throw;
  }
  ImageRgb image(static_cast<int>(w), static_cast<int>(h));
  auto fail = [&]() -> Error {
    std::string why = png.message;
    png_image_free(&png);
    return Error(path + ": cannot read PNG: " + why);
  };
  if (sixteen) {
    // libpng's linear output associates alpha (colour * alpha): divided
    // out again to get the file's straight colour (lost where alpha is 0).
    png.format = PNG_FORMAT_LINEAR_RGB_ALPHA;
    std::vector<png_uint_16> px(size_t(w) * size_t(h) * 4);
    if (!png_image_finish_read(&png, nullptr, px.data(), 0, nullptr)) throw fail();
    for (size_t i = 0; i < image.pixelCount(); ++i) {
      const float a = px[4 * i + 3];
      const float k = a > 0 ? 1.0f / a : 0.0f;
      image.pixels[i] = Rgb(px[4 * i] * k, px[4 * i + 1] * k, px[4 * i + 2] * k);
    }
  } else {
    // RGBA, not RGB: without an alpha channel in the output libpng would
    // composite onto a background; colour must stay the file's own.
    png.format = PNG_FORMAT_RGBA;
    std::vector<png_byte> px(size_t(w) * size_t(h) * 4);
    if (!png_image_finish_read(&png, nullptr, px.data(), 0, nullptr)) throw fail();
    float table[256];
    for (int v = 0; v < 256; ++v) table[v] = srgbDecode(v / 255.0f);
    for (size_t i = 0; i < image.pixelCount(); ++i)
      image.pixels[i] = Rgb(table[px[4 * i]], table[px[4 * i + 1]], table[px[4 * i + 2]]);
  }
  return image;
}

std::string previewPathFor(const std::string& outputPath) {
  const size_t slash = outputPath.find_last_of('/');
  const size_t nameStart = slash == std::string::npos ? 0 : slash + 1;
  size_t dot = outputPath.find_last_of('.');
  // A dot that is in a directory name, or that starts the file name
  // (".hidden"), is not an extension.
  if (dot == std::string::npos || dot <= nameStart) return outputPath + ".png";
  std::string ext = outputPath.substr(dot);
  for (char& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  const std::string stem = outputPath.substr(0, dot);
  if (ext == ".png") return stem + ".preview.png";
  return stem + ".png";
}

}  // namespace tdpm::image
