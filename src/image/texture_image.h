// image/texture_image.h — reading the picture behind an image texture: any
// format read_image.h reads, plus TGA, as linear RGB, with pbrt's
// "encoding" rule for 8-bit files. Owns TexelEncoding and readTextureImage.
#pragma once
#include <string>

#include "image/image.h"

namespace tdpm::image {

// How 8-bit codes c (PNG of 8 bits or fewer, TGA) become linear values:
// the sRGB curve, c / 255, or (c / 255)^gamma. Floating-point and 16-bit
// files (EXR, PFM, HDR, 16-bit PNG) are linear already and read as stored,
// as pbrt does.
struct TexelEncoding {
  enum class Kind { Srgb, Linear, Gamma };
  Kind kind = Kind::Srgb;
  float gamma = 2.2f;
  bool operator==(const TexelEncoding& o) const { return kind == o.kind && (kind != Kind::Gamma || gamma == o.gamma); }
};

// "sRGB", "linear" or "gamma <g>" as pbrt-v4 writes it.
std::string encodingName(const TexelEncoding& e);

// Row 0 at the top. Throws tdpm::Error "<path>: <reason>" (missing,
// unreadable or malformed file; no texels; a texel that is not finite or
// is negative). *eightBit (if given) tells whether the encoding applied.
ImageRgb readTextureImage(const std::string& path, const TexelEncoding& encoding, bool* eightBit = nullptr);

}  // namespace tdpm::image
