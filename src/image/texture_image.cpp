// image/texture_image.cpp — see texture_image.h. TGA is recognised by its
// extension (the format has no signature); everything else by content.
#include "image/texture_image.h"

#include <cctype>
#include <cmath>
#include <cstdio>

#include "core/error.h"
#include "image/image_limits.h"
#include "image/png.h"
#include "image/read_image.h"
#include "image/tga.h"

namespace tdpm::image {

namespace {

bool hasTgaExtension(const std::string& path) {
  if (path.size() < 4) return false;
  std::string ext = path.substr(path.size() - 4);
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".tga";
}

// The bit depth in a PNG's IHDR chunk (byte 24 of the file).
int pngBitDepth(const std::string& path) {
  uint64_t size = 0;
  std::FILE* f = openRegularFile(path, size);
  unsigned char h[25] = {};
  size_t n = std::fread(h, 1, sizeof h, f);
  std::fclose(f);
  return n == sizeof h ? h[24] : 8;
}

float decode(unsigned code, const TexelEncoding& e) {
  float v = float(code) / 255.0f;
  switch (e.kind) {
    case TexelEncoding::Kind::Srgb: return srgbDecode(v);
    case TexelEncoding::Kind::Linear: return v;
    case TexelEncoding::Kind::Gamma: return std::pow(v, e.gamma);
  }
  return v;
}

ImageRgb fromCodes(const ImageRgb8& in, const TexelEncoding& e) {
  float table[256];
  for (unsigned c = 0; c < 256; ++c) table[c] = decode(c, e);
  ImageRgb out(in.width, in.height);
  for (size_t i = 0; i < out.pixels.size(); ++i)
    out.pixels[i] = {table[in.rgb[3 * i]], table[in.rgb[3 * i + 1]], table[in.rgb[3 * i + 2]]};
  return out;
}

}  // namespace

std::string encodingName(const TexelEncoding& e) {
  switch (e.kind) {
    case TexelEncoding::Kind::Srgb: return "sRGB";
    case TexelEncoding::Kind::Linear: return "linear";
    case TexelEncoding::Kind::Gamma: {
      char buf[32];
      std::snprintf(buf, sizeof buf, "gamma %.9g", double(e.gamma));
      return buf;
    }
  }
  return "sRGB";
}

ImageRgb readTextureImage(const std::string& path, const TexelEncoding& encoding, bool* eightBit) {
  ImageRgb img;
  bool codes = false;
  if (hasTgaExtension(path)) {
    img = fromCodes(readTga(path), encoding);
    codes = true;
  } else {
    ImageFormat format = detectImageFormat(path);
    img = readImage(path).color;
    if (format == ImageFormat::Png && pngBitDepth(path) <= 8) {
      codes = true;
      if (encoding.kind != TexelEncoding::Kind::Srgb) {
        // readPngLinear decoded the 256 sRGB levels exactly: recover the
        // codes, then apply the asked-for encoding.
        float table[256];
        for (unsigned c = 0; c < 256; ++c) table[c] = decode(c, encoding);
        for (Rgb& p : img.pixels)
          for (int k = 0; k < 3; ++k) {
            long c = std::lround(srgbEncode(p[k]) * 255.0f);
            p[k] = table[c < 0 ? 0 : c > 255 ? 255 : c];
          }
      }
    }
  }
  if (img.empty()) throw Error(path + ": the image has no texels");
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const Rgb& c = img.at(x, y);
      if (!(c.r >= 0 && c.g >= 0 && c.b >= 0) || !isFinite(c))
        throw Error(path + ": texel (" + std::to_string(x) + ", " + std::to_string(y) +
                    ") is not finite and non-negative; a texture's values must be");
    }
  if (eightBit) *eightBit = codes;
  return img;
}

}  // namespace tdpm::image
