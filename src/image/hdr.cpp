// image/hdr.cpp — the strict Radiance RGBE reader and writer of image/hdr.h.
// The reading follows Radiance's freadcolrs (src/common/color.c): a
// scanline of 8..32767 pixels may be new-style RLE, recognised by its first
// bytes 2, 2 and a length matching the scanline; anything else is flat
// pixels where (1, 1, 1, n) repeats the previous pixel n << shift times.
#include "image/hdr.h"

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

// A header line without its newline; false at the end of the file or for a
// line over 4096 characters (headers are short text).
bool readLine(std::FILE* f, std::string& line) {
  line.clear();
  for (;;) {
    int c = std::fgetc(f);
    if (c == EOF) return false;
    if (c == '\n') return true;
    if (line.size() >= 4096) return false;
    line += char(c);
  }
}

Rgb rgbeToRgb(const unsigned char* p, float scale) {
  if (p[3] == 0) return Rgb();
  // Radiance's colr_color: (mantissa + 0.5) * 2^(exponent - 136).
  const float f = std::ldexp(1.0f, int(p[3]) - (128 + 8)) * scale;
  return Rgb((p[0] + 0.5f) * f, (p[1] + 0.5f) * f, (p[2] + 0.5f) * f);
}

struct Orientation {
  bool yFirst = true;       // scanlines run along X (the usual case)
  bool yDown = true;        // -Y: first scanline at the top
  bool xRight = true;       // +X: left to right
  int64_t width = 0, height = 0;
};

// "s1 A n1 s2 B n2" with {A, B} = {X, Y}, signs + or -, sizes 1..65536.
bool parseResolution(const std::string& line, Orientation& o) {
  char s1, a1, s2, a2;
  long long n1, n2;
  char extra;
  if (std::sscanf(line.c_str(), " %c%c %lld %c%c %lld %c", &s1, &a1, &n1, &s2, &a2, &n2, &extra) != 6) return false;
  auto sign = [](char s) { return s == '+' || s == '-'; };
  if (!sign(s1) || !sign(s2) || a1 == a2 || (a1 != 'X' && a1 != 'Y') || (a2 != 'X' && a2 != 'Y')) return false;
  if (n1 < 1 || n2 < 1 || n1 > kMaxImageSide || n2 > kMaxImageSide) return false;
  o.yFirst = a1 == 'Y';
  const char ySign = o.yFirst ? s1 : s2, xSign = o.yFirst ? s2 : s1;
  o.yDown = ySign == '-';
  o.xRight = xSign == '+';
  o.height = o.yFirst ? n1 : n2;
  o.width = o.yFirst ? n2 : n1;
  return true;
}

// Decodes one scanline of `n` pixels into `out` (4 bytes each). Returns ""
// or what is wrong.
std::string readScanline(std::FILE* f, int64_t n, unsigned char* out) {
  unsigned char head[4];
  if (std::fread(head, 1, 4, f) != 4) return "the file ends";
  const bool newRle = n >= 8 && n <= 0x7fff && head[0] == 2 && head[1] == 2 && !(head[2] & 0x80);
  if (newRle) {
    if ((int64_t(head[2]) << 8 | head[3]) != n)
      return "its run-length header says " + std::to_string(int64_t(head[2]) << 8 | head[3]) + " pixels, the image " +
             std::to_string(n);
    for (int c = 0; c < 4; ++c)
      for (int64_t x = 0; x < n;) {
        int count = std::fgetc(f);
        if (count == EOF) return "the file ends";
        if (count > 128) {  // a run: count - 128 copies of the next byte
          count -= 128;
          int v = std::fgetc(f);
          if (v == EOF) return "the file ends";
          if (x + count > n) return "a run passes the end of the scanline";
          for (int k = 0; k < count; ++k) out[4 * (x + k) + c] = (unsigned char)v;
          x += count;
        } else {  // count literal bytes
          if (count == 0) return "a run of length 0";
          if (x + count > n) return "a run passes the end of the scanline";
          for (int k = 0; k < count; ++k) {
            int v = std::fgetc(f);
            if (v == EOF) return "the file ends";
            out[4 * (x + k) + c] = (unsigned char)v;
          }
          x += count;
        }
      }
    return "";
  }
  // Flat pixels, with old-style repeats.
  int shift = 0;
  for (int64_t x = 0; x < n;) {
    unsigned char p[4];
    if (x == 0) std::memcpy(p, head, 4);
    else if (std::fread(p, 1, 4, f) != 4) return "the file ends";
    if (p[0] == 1 && p[1] == 1 && p[2] == 1) {
      if (x == 0) return "a repeat code before the first pixel";
      if (shift > 16) return "repeat codes overflow";
      const int64_t count = int64_t(p[3]) << shift;
      if (x + count > n) return "a repeat passes the end of the scanline";
      for (int64_t k = 0; k < count; ++k) std::memcpy(out + 4 * (x + k), out + 4 * (x - 1), 4);
      x += count;
      shift += 8;
    } else {
      std::memcpy(out + 4 * x, p, 4);
      ++x;
      shift = 0;
    }
  }
  return "";
}

}  // namespace

ImageRgb readHdr(const std::string& path) {
  uint64_t fileSize = 0;
  File f(openRegularFile(path, fileSize));
  std::string line;
  if (!readLine(f.get(), line) || (line.rfind("#?RADIANCE", 0) != 0 && line.rfind("#?RGBE", 0) != 0))
    throw Error(path + ": not a Radiance HDR file (it must start with '#?RADIANCE' or '#?RGBE')");
  double exposure = 1.0;
  int lineNumber = 1;
  for (;;) {
    ++lineNumber;
    if (!readLine(f.get(), line))
      throw Error(path + ": Radiance header line " + std::to_string(lineNumber) +
                  ": the header does not end (no empty line before the resolution) or a line is over 4096 characters");
    if (line.empty()) break;
    if (line.rfind("FORMAT=", 0) == 0) {
      const std::string format = line.substr(7);
      if (format == "32-bit_rle_xyze")
        throw Error(path + ": Radiance header line " + std::to_string(lineNumber) +
                    ": FORMAT=32-bit_rle_xyze (CIE XYZ) is not read; tdpm reads 32-bit_rle_rgbe");
      if (format != "32-bit_rle_rgbe")
        throw Error(path + ": Radiance header line " + std::to_string(lineNumber) + ": unknown FORMAT '" + format +
                    "' (tdpm reads 32-bit_rle_rgbe)");
    } else if (line.rfind("EXPOSURE=", 0) == 0) {
      char* end = nullptr;
      const double e = std::strtod(line.c_str() + 9, &end);
      while (end && (*end == ' ' || *end == '\t' || *end == '\r')) ++end;
      if (!end || *end != 0 || !std::isfinite(e) || e <= 0)
        throw Error(path + ": Radiance header line " + std::to_string(lineNumber) +
                    ": EXPOSURE must be a positive number, got '" + line.substr(9) + "'");
      exposure *= e;  // several EXPOSURE lines multiply (Radiance's rule)
    }
  }
  ++lineNumber;
  Orientation o;
  if (!readLine(f.get(), line) || !parseResolution(line, o))
    throw Error(path + ": Radiance header line " + std::to_string(lineNumber) +
                ": expected a resolution such as '-Y 480 +X 640' (each size 1.." + std::to_string(kMaxImageSide) +
                "), got '" + line.substr(0, 80) + "'");
  if (!std::isfinite(1.0 / exposure) || exposure == 0) throw Error(path + ": Radiance EXPOSURE product is out of range");
  const int64_t scanlineCount = o.yFirst ? o.height : o.width;
  const long headerEnd = std::ftell(f.get());
  const uint64_t dataBytes = headerEnd < 0 ? 0 : fileSize - uint64_t(headerEnd);
  // Every scanline takes at least 4 bytes, however it is encoded.
  if (uint64_t(scanlineCount) * 4 > dataBytes)
    throw Error(path + ": Radiance file declares " + std::to_string(scanlineCount) + " scanlines (" + line +
                "), which need at least " + std::to_string(uint64_t(scanlineCount) * 4) + " bytes; it has " +
                std::to_string(dataBytes) + " after its header");

  // Decoded RGBE bytes (4 per pixel) and the image after: both sized from
  // the declared resolution, so the machine must have that memory; but the
  // RGBE buffer only grows as scanlines actually decode.
  checkDecodedImageFits(path, "Radiance HDR", o.width, o.height, 4 + sizeof(Rgb));
  const int64_t scanlines = o.yFirst ? o.height : o.width, length = o.yFirst ? o.width : o.height;
  std::vector<unsigned char> rgbe;
  std::vector<unsigned char> scan(size_t(length) * 4);
  for (int64_t s = 0; s < scanlines; ++s) {
    std::string why = readScanline(f.get(), length, scan.data());
    if (!why.empty())
      throw Error(path + ": Radiance pixel data, scanline " + std::to_string(s) + " of " + std::to_string(scanlines) +
                  ": " + why);
    rgbe.insert(rgbe.end(), scan.begin(), scan.end());
  }
  // Trailing bytes after the last scanline mean the file is not what its
  // header says.
  if (std::fgetc(f.get()) != EOF)
    throw Error(path + ": Radiance file has data after its " + std::to_string(scanlines) + " scanlines");

  const float scale = float(1.0 / exposure);
  ImageRgb image(static_cast<int>(o.width), static_cast<int>(o.height));
  for (int64_t s = 0; s < scanlines; ++s)
    for (int64_t i = 0; i < length; ++i) {
      int64_t x = o.yFirst ? i : s, y = o.yFirst ? s : i;
      if (!o.xRight) x = o.width - 1 - x;
      if (!o.yDown) y = o.height - 1 - y;
      image.at(int(x), int(y)) = rgbeToRgb(&rgbe[size_t(s * length + i) * 4], scale);
    }
  return image;
}

namespace {

// Radiance's setcolr: the largest channel's mantissa in 128..255.
void rgbToRgbe(const Rgb& c, unsigned char* p) {
  const float m = std::max(c.r, std::max(c.g, c.b));
  if (!(m > 1e-32f) || !std::isfinite(m)) {
    p[0] = p[1] = p[2] = p[3] = 0;
    return;
  }
  int e;
  const float f = std::frexp(m, &e) * 256.0f / m;  // m = frac * 2^e, frac in [0.5, 1)
  auto mant = [&](float v) { return (unsigned char)std::min(255.0f, std::max(0.0f, v * f)); };
  p[0] = mant(c.r);
  p[1] = mant(c.g);
  p[2] = mant(c.b);
  p[3] = (unsigned char)(e + 128);
}

void appendRleComponent(std::string& out, const unsigned char* px, int n, int c) {
  for (int x = 0; x < n;) {
    // A run of at least 3 equal bytes is worth coding as a run.
    int run = 1;
    while (x + run < n && run < 127 && px[4 * (x + run) + c] == px[4 * x + c]) ++run;
    if (run >= 3) {
      out += char(128 + run);
      out += char(px[4 * x + c]);
      x += run;
      continue;
    }
    int lit = 0;
    while (x + lit < n && lit < 128) {
      int r = 1;
      while (x + lit + r < n && r < 3 && px[4 * (x + lit + r) + c] == px[4 * (x + lit) + c]) ++r;
      if (r >= 3) break;
      ++lit;
    }
    out += char(lit);
    for (int k = 0; k < lit; ++k) out += char(px[4 * (x + k) + c]);
    x += lit;
  }
}

}  // namespace

void writeHdr(const std::string& path, const ImageRgb& image, bool runLengthEncode) {
  TDPM_ASSERT(!image.empty(), "writeHdr: empty image");
  std::string out = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y " + std::to_string(image.height) + " +X " +
                    std::to_string(image.width) + "\n";
  const int w = image.width;
  const bool rle = runLengthEncode && w >= 8 && w <= 0x7fff;
  std::vector<unsigned char> px(size_t(w) * 4);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < w; ++x) rgbToRgbe(image.at(x, y), &px[size_t(x) * 4]);
    if (rle) {
      out += char(2);
      out += char(2);
      out += char(w >> 8);
      out += char(w & 0xff);
      for (int c = 0; c < 4; ++c) appendRleComponent(out, px.data(), w, c);
    } else {
      out.append(reinterpret_cast<const char*>(px.data()), px.size());
    }
  }
  writeTextFileAtomic(path, out);
}

}  // namespace tdpm::image
