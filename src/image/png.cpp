// image/png.cpp — tone mapping to sRGB 8-bit and PNG I/O through libpng's
// simplified API (png_image), which reports errors in a message field
// instead of longjmp, so no setjmp is needed around C++ objects.
#include "image/png.h"

#include <png.h>

#include <cctype>
#include <cmath>

#include "core/atomic_file.h"

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
