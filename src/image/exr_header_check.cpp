// image/exr_header_check.cpp — walks OpenEXR headers byte by byte (see the
// header for why). Layout: magic (4), version (4, flags in byte 5), then
// one header (single part) or a list of headers ended by an empty one
// (multi-part); a header is attributes "name\0type\0<int32 size><size bytes>"
// ended by an empty name. All integers are little-endian.
#include "image/exr_header_check.h"

#include <map>

#include "image/image_limits.h"

namespace tdpm::image {

uint64_t exrMaxCompressionRatio(int code) {
  static const uint64_t ratios[10] = {1, 64, 1032, 1032, 1032, 1376, 11, 11, 66048, 66048};
  return code >= 0 && code < 10 ? ratios[code] : 0;
}

namespace {

const char* compressionName(int code) {
  static const char* names[10] = {"NONE", "RLE", "ZIPS", "ZIP", "PIZ", "PXR24", "B44", "B44A", "DWAA", "DWAB"};
  return code >= 0 && code < 10 ? names[code] : "unknown";
}

// Sequential reader that never reads past the end of the file and knows
// how much is left, so a claimed size can be checked before it is used.
class Reader {
 public:
  explicit Reader(std::FILE* f) : f_(f) {
    if (std::fseek(f, 0, SEEK_END) == 0) {
      long end = std::ftell(f);
      size_ = end > 0 ? uint64_t(end) : 0;
    }
    std::fseek(f, 0, SEEK_SET);
  }
  uint64_t pos() const { return pos_; }
  uint64_t size() const { return size_; }
  uint64_t left() const { return size_ - pos_; }
  bool bytes(void* out, uint64_t n) {
    if (n > left() || std::fread(out, 1, size_t(n), f_) != n) return false;
    pos_ += n;
    return true;
  }
  bool skip(uint64_t n) {
    if (n > left() || std::fseek(f_, long(n), SEEK_CUR) != 0) return false;
    pos_ += n;
    return true;
  }
  bool u32(uint32_t& v) {
    unsigned char b[4];
    if (!bytes(b, 4)) return false;
    v = uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
    return true;
  }
  bool i32(int32_t& v) {
    uint32_t u;
    if (!u32(u)) return false;
    v = int32_t(u);
    return true;
  }
  // A NUL-terminated string of at most 255 characters (OpenEXR's longest
  // name); false at the end of the file or if longer.
  bool name(std::string& out) {
    out.clear();
    for (;;) {
      char c;
      if (!bytes(&c, 1)) return false;
      if (c == 0) return true;
      if (out.size() >= 255) return false;
      out += c;
    }
  }

 private:
  std::FILE* f_;
  uint64_t size_ = 0;
  uint64_t pos_ = 0;
};

// The byte size of every fixed-size attribute type OpenEXR 3.1 knows. Its
// readers of these types read exactly this many bytes, whatever the
// declared size says.
int fixedSize(const std::string& type) {
  static const std::map<std::string, int> sizes = {
      {"box2i", 16},  {"box2f", 16},    {"chromaticities", 32}, {"compression", 1}, {"double", 8},
      {"envmap", 1},  {"float", 4},     {"int", 4},             {"keycode", 28},    {"lineOrder", 1},
      {"m33f", 36},   {"m33d", 72},     {"m44f", 64},           {"m44d", 128},      {"rational", 8},
      {"tiledesc", 9}, {"timecode", 8}, {"v2i", 8},             {"v2f", 8},         {"v2d", 16},
      {"v3i", 12},    {"v3f", 12},      {"v3d", 24},            {"deepImageState", 1}};
  auto it = sizes.find(type);
  return it == sizes.end() ? -1 : it->second;
}

std::string quoted(const std::string& name, const std::string& type) {
  return "attribute '" + name + "' (" + type + ")";
}

// What one part's header says about its size; checked once it is read.
struct PartShape {
  bool hasWindow = false;
  int64_t width = 0, height = 0;
  bool hasTiles = false;
  uint32_t tileX = 0, tileY = 0;
  int compression = -1;             // -1: no compression attribute (OpenEXR reports it)
  uint64_t bytesPerPixel = 0;       // full-resolution channels, as stored (HALF 2, FLOAT and UINT 4)
};

std::string checkShape(const PartShape& s, uint64_t fileSize) {
  if (!s.hasWindow) return "";  // OpenEXR reports the missing attribute itself
  const std::string size = std::to_string(s.width) + "x" + std::to_string(s.height);
  if (s.width <= 0 || s.height <= 0) return "data window is empty (" + size + ")";
  // Each side: both can be near 2^32, and their product overflow.
  if (s.width > kMaxImageSide || s.height > kMaxImageSide)
    return "data window " + size + " is larger than " + std::to_string(kMaxImageSide) + " pixels per side";
  if (s.hasTiles) {
    if (s.tileX == 0 || s.tileY == 0) return "tile size is zero";
    const int64_t tiles = ((s.width + s.tileX - 1) / s.tileX) * ((s.height + s.tileY - 1) / s.tileY);
    if (tiles > kMaxExrTiles)
      return std::to_string(s.tileX) + "x" + std::to_string(s.tileY) + " tiles make " + std::to_string(tiles) +
             " tiles, more than " + std::to_string(kMaxExrTiles);
  }
  // What the pixels take decoded, against the most this file could hold:
  // a few hundred bytes must not be able to claim gigabytes.
  const uint64_t ratio = exrMaxCompressionRatio(s.compression);
  if (s.compression < 0 || ratio == 0) return "";  // OpenEXR rejects a missing or unknown compression
  const uint64_t decoded = uint64_t(s.width) * uint64_t(s.height) * s.bytesPerPixel;
  if (decoded / ratio > fileSize)
    return "data window " + size + " with " + std::to_string(s.bytesPerPixel) + " bytes per pixel needs " +
           std::to_string(decoded) + " bytes decoded, more than a " + std::to_string(fileSize) + "-byte file holds with " +
           compressionName(s.compression) + " compression (at most " + std::to_string(ratio) + " to 1)";
  return "";
}

// One attribute's value, starting after its size field. Returns "" or the problem.
std::string checkValue(Reader& in, const std::string& name, const std::string& type, int64_t size,
                       PartShape& shape) {
  const uint64_t start = in.pos();
  const std::string what = quoted(name, type);
  const std::string truncated = what + " runs past the end of the file";
  const int fixed = fixedSize(type);
  if (fixed >= 0) {
    if (size != fixed)
      return what + " declares " + std::to_string(size) + " bytes; its type has " + std::to_string(fixed);
    if (type == "box2i" && name == "dataWindow") {
      int32_t b[4];
      for (int32_t& v : b)
        if (!in.i32(v)) return truncated;
      shape.hasWindow = true;
      shape.width = int64_t(b[2]) - b[0] + 1;
      shape.height = int64_t(b[3]) - b[1] + 1;
      return "";
    }
    if (type == "tiledesc" && name == "tiles") {
      if (!in.u32(shape.tileX) || !in.u32(shape.tileY) || !in.skip(1)) return truncated;
      shape.hasTiles = true;
      return "";
    }
    if (type == "compression" && name == "compression") {
      unsigned char code;
      if (!in.bytes(&code, 1)) return truncated;
      shape.compression = code;
      return "";
    }
    if (type == "int" && name == "chunkCount") {
      int32_t count;
      if (!in.i32(count)) return truncated;
      // Sizes the chunk offset table of parts of unknown type.
      if (count < 0 || count > 4 * kMaxExrTiles) return what + " is " + std::to_string(count);
      return "";
    }
    return in.skip(uint64_t(size)) ? "" : truncated;
  }
  if (type == "chlist") {
    // Channels (name, pixel type, pLinear + 3 reserved, x and y sampling)
    // until an empty name; OpenEXR ignores the declared size here.
    const bool isChannels = name == "channels";
    if (isChannels) shape.bytesPerPixel = 0;  // a repeated attribute replaces the earlier one
    for (std::string channel;;) {
      if (!in.name(channel)) return truncated;
      if (channel.empty()) break;
      int32_t pixelType, xSampling, ySampling;
      if (!in.i32(pixelType) || !in.skip(4) || !in.i32(xSampling) || !in.i32(ySampling)) return truncated;
      if (isChannels && xSampling == 1 && ySampling == 1) shape.bytesPerPixel += pixelType == 1 ? 2 : 4;
      if (in.pos() - start > uint64_t(size)) break;
    }
    if (in.pos() - start != uint64_t(size))
      return what + " declares " + std::to_string(size) + " bytes; its channels take " +
             std::to_string(in.pos() - start);
    return "";
  }
  if (type == "preview") {
    // Width and height, then RGBA8 pixels: OpenEXR allocates w*h*4 bytes
    // from these two numbers alone.
    uint32_t w, h;
    if (size < 8 || !in.u32(w) || !in.u32(h)) return truncated;
    const uint64_t pixels = uint64_t(w) * h * 4;
    if (pixels != uint64_t(size) - 8)
      return what + " of " + std::to_string(w) + "x" + std::to_string(h) + " declares " + std::to_string(size) +
             " bytes";
    return in.skip(pixels) ? "" : truncated;
  }
  // string, stringvector, floatvector, idmanifest and unknown (opaque)
  // types: read as exactly `size` bytes, already checked against the file.
  return in.skip(uint64_t(size)) ? "" : truncated;
}

}  // namespace

std::string checkExrHeader(std::FILE* f) {
  Reader in(f);  // from the start of the file
  unsigned char start[8];
  if (!in.bytes(start, 8)) return "file ends inside the version field";
  const bool multipart = (start[5] & 0x10) != 0;
  for (int part = 0; part < 1 << 16; ++part) {
    PartShape shape;
    int attributes = 0;
    for (std::string name, type;; ++attributes) {
      if (!in.name(name)) return "header " + std::to_string(part) + " is cut short or has a name over 255 characters";
      if (name.empty()) break;  // end of this header
      if (!in.name(type)) return "attribute '" + name + "' has no type (file cut short)";
      int32_t size;
      if (!in.i32(size)) return quoted(name, type) + " has no size (file cut short)";
      if (size < 0 || uint64_t(size) > in.left())
        return quoted(name, type) + " claims " + std::to_string(size) + " bytes, but the file has " +
               std::to_string(in.left()) + " left";
      std::string problem = checkValue(in, name, type, size, shape);
      if (!problem.empty()) return problem;
    }
    std::string problem = checkShape(shape, in.size());
    if (!problem.empty()) return problem;
    // A single-part file has one header; a multi-part file ends its list
    // of headers with an empty one.
    if (!multipart || attributes == 0) return "";
  }
  return "more than 65536 parts";
}

}  // namespace tdpm::image
