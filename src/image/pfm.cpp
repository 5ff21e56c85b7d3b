// image/pfm.cpp — the strict PFM reader and writer of image/pfm.h. The
// header is parsed token by token with bounded lengths; the pixel data is
// streamed row by row, so memory is the image plus one row.
#include "image/pfm.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <vector>

#include "core/atomic_file.h"
#include "image/image_limits.h"

namespace tdpm::image {
namespace {

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

bool isSpace(int c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

// Next header token: skips whitespace, then reads up to 32 non-space
// characters. Returns false at the end of the file or for a longer token.
bool token(std::FILE* f, std::string& out, int& after) {
  int c;
  do c = std::fgetc(f);
  while (c != EOF && isSpace(c));
  out.clear();
  while (c != EOF && !isSpace(c)) {
    if (out.size() >= 32) return false;
    out += char(c);
    c = std::fgetc(f);
  }
  after = c;  // the character that ended the token (EOF or one whitespace)
  return !out.empty();
}

// A positive decimal size: digits only, at most kMaxImageSide.
bool parseSide(const std::string& t, int64_t& v) {
  if (t.empty() || t.size() > 9) return false;
  v = 0;
  for (char ch : t) {
    if (ch < '0' || ch > '9') return false;
    v = v * 10 + (ch - '0');
  }
  return v >= 1;
}

float decode(const unsigned char* b, bool littleEndian) {
  uint32_t u = littleEndian ? uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24
                            : uint32_t(b[3]) | uint32_t(b[2]) << 8 | uint32_t(b[1]) << 16 | uint32_t(b[0]) << 24;
  float v;
  std::memcpy(&v, &u, 4);
  return v;
}

}  // namespace

ImageRgb readPfm(const std::string& path) {
  uint64_t fileSize = 0;
  File f(openRegularFile(path, fileSize));
  char magic[2] = {0, 0};
  if (std::fread(magic, 1, 2, f.get()) != 2 || magic[0] != 'P' || (magic[1] != 'F' && magic[1] != 'f'))
    throw Error(path + ": not a PFM file (it must start with 'PF' or 'Pf')");
  const int channels = magic[1] == 'F' ? 3 : 1;
  int next = std::fgetc(f.get());
  if (!isSpace(next)) throw Error(path + ": PFM header: expected whitespace after '" + std::string(magic, 2) + "'");

  std::string t;
  int after = 0;
  int64_t w = 0, h = 0;
  if (!token(f.get(), t, after) || !parseSide(t, w))
    throw Error(path + ": PFM header: width must be a positive whole number, got '" + t + "'");
  if (!token(f.get(), t, after) || !parseSide(t, h))
    throw Error(path + ": PFM header: height must be a positive whole number, got '" + t + "'");
  if (w > kMaxImageSide || h > kMaxImageSide)
    throw Error(path + ": PFM image " + std::to_string(w) + "x" + std::to_string(h) + " is larger than " +
                std::to_string(kMaxImageSide) + " pixels per side");
  if (!token(f.get(), t, after)) throw Error(path + ": PFM header: missing scale (file cut short)");
  char* end = nullptr;
  const double scale = std::strtod(t.c_str(), &end);
  if (end != t.c_str() + t.size() || !std::isfinite(scale) || scale == 0.0)
    throw Error(path + ": PFM header: scale must be a finite non-zero number, got '" + t + "'");
  if (!isSpace(after)) throw Error(path + ": PFM header: no whitespace after the scale (file cut short)");

  // The header ends with that one whitespace character; the rest is data,
  // and must be exactly the declared pixels.
  const long headerEnd = std::ftell(f.get());
  const uint64_t rowBytes = uint64_t(w) * uint64_t(channels) * 4;
  const uint64_t expected = rowBytes * uint64_t(h);
  const uint64_t actual = headerEnd < 0 ? 0 : fileSize - uint64_t(headerEnd);
  if (actual != expected)
    throw Error(path + ": PFM " + std::to_string(w) + "x" + std::to_string(h) + (channels == 3 ? " colour" : " grey") +
                " needs " + std::to_string(expected) + " bytes of pixel data after the header, the file has " +
                std::to_string(actual));
  checkDecodedImageFits(path, "PFM", w, h, sizeof(Rgb));

  const bool littleEndian = scale < 0;
  const float factor = float(std::abs(scale));
  ImageRgb image(static_cast<int>(w), static_cast<int>(h));
  std::vector<unsigned char> row(rowBytes);
  for (int64_t fileRow = 0; fileRow < h; ++fileRow) {
    if (std::fread(row.data(), 1, row.size(), f.get()) != row.size())
      throw Error(path + ": PFM file ends inside row " + std::to_string(fileRow) + " of its pixel data");
    const int y = int(h - 1 - fileRow);  // stored bottom to top
    for (int x = 0; x < int(w); ++x) {
      const unsigned char* p = row.data() + size_t(x) * size_t(channels) * 4;
      Rgb& out = image.at(x, y);
      if (channels == 3) out = Rgb(decode(p, littleEndian), decode(p + 4, littleEndian), decode(p + 8, littleEndian));
      else out = Rgb(decode(p, littleEndian));
      if (factor != 1.0f) out = Rgb(out.r * factor, out.g * factor, out.b * factor);
    }
  }
  return image;
}

void writePfm(const std::string& path, const ImageRgb& image) {
  TDPM_ASSERT(!image.empty(), "writePfm: empty image");
  std::string bytes = "PF\n" + std::to_string(image.width) + " " + std::to_string(image.height) + "\n-1\n";
  const size_t header = bytes.size();
  bytes.resize(header + image.pixelCount() * 12);
  size_t o = header;
  for (int y = image.height - 1; y >= 0; --y)
    for (int x = 0; x < image.width; ++x)
      for (int c = 0; c < 3; ++c) {
        float v = image.at(x, y)[c];
        uint32_t u;
        std::memcpy(&u, &v, 4);
        for (int k = 0; k < 4; ++k) bytes[o++] = char((u >> (8 * k)) & 0xff);
      }
  writeTextFileAtomic(path, bytes);
}

}  // namespace tdpm::image
