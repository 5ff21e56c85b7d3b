// image/image_header.cpp — sizes from image headers (see image_header.h).
// Reads at most the first 64 KiB of a file (1 MiB for EXR attributes);
// every field is bounds-checked and anything odd gives nullopt.
#include "image/image_header.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <sstream>
#include <vector>

#include "image/image_limits.h"

namespace tdpm::image {
namespace {

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

std::vector<unsigned char> readPrefix(const std::string& path, size_t limit) {
  uint64_t size = 0;
  std::unique_ptr<std::FILE, FileCloser> f(openRegularFile(path, size));
  std::vector<unsigned char> bytes(size_t(std::min<uint64_t>(size, limit)));
  bytes.resize(std::fread(bytes.data(), 1, bytes.size(), f.get()));
  return bytes;
}

bool sideOk(int64_t v) { return v >= 1 && v <= kMaxImageSide; }

uint32_t be32(const unsigned char* p) { return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | p[3]; }
int32_t le32(const unsigned char* p) { return int32_t(uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24); }

std::optional<ImageHeader> pngHeader(const std::vector<unsigned char>& b) {
  // signature (8), IHDR length (4), "IHDR", width, height, depth, colour type
  if (b.size() < 26 || std::memcmp(b.data() + 12, "IHDR", 4) != 0) return std::nullopt;
  ImageHeader h;
  h.format = ImageFormat::Png;
  h.width = int(std::min<uint32_t>(be32(b.data() + 16), 1u << 30));
  h.height = int(std::min<uint32_t>(be32(b.data() + 20), 1u << 30));
  switch (b[25]) {
    case 0: h.channels = 1; break;
    case 2: case 3: h.channels = 3; break;
    case 4: h.channels = 2; break;
    case 6: h.channels = 4; break;
    default: return std::nullopt;
  }
  return h;
}

std::optional<ImageHeader> pfmHeader(const std::vector<unsigned char>& b) {
  std::istringstream in(std::string(b.begin(), b.end()));
  std::string magic;
  long long w = 0, h = 0;
  if (!(in >> magic >> w >> h) || (magic != "PF" && magic != "Pf") || !sideOk(w) || !sideOk(h)) return std::nullopt;
  return ImageHeader{ImageFormat::Pfm, int(w), int(h), magic == "PF" ? 3 : 1};
}

std::optional<ImageHeader> hdrHeader(const std::vector<unsigned char>& b) {
  std::string text(b.begin(), b.end());
  size_t blank = text.find("\n\n");
  if (blank == std::string::npos) return std::nullopt;
  size_t start = blank + 2, end = text.find('\n', start);
  if (end == std::string::npos) return std::nullopt;
  char a1[3] = {0}, a2[3] = {0};
  long long n1 = 0, n2 = 0;
  std::string line = text.substr(start, end - start);
  if (std::sscanf(line.c_str(), "%2s %lld %2s %lld", a1, &n1, a2, &n2) != 4) return std::nullopt;
  bool yFirst = a1[1] == 'Y' && a2[1] == 'X', xFirst = a1[1] == 'X' && a2[1] == 'Y';
  if (!yFirst && !xFirst) return std::nullopt;
  long long w = yFirst ? n2 : n1, h = yFirst ? n1 : n2;
  if (!sideOk(w) || !sideOk(h)) return std::nullopt;
  return ImageHeader{ImageFormat::Hdr, int(w), int(h), 3};
}

// Attributes after the magic and version: name\0 type\0 int32 size, value.
std::optional<ImageHeader> exrHeader(const std::vector<unsigned char>& b) {
  size_t p = 8;
  auto cstr = [&](std::string& out) {
    const void* z = p < b.size() ? std::memchr(b.data() + p, 0, std::min<size_t>(b.size() - p, 256)) : nullptr;
    if (!z) return false;
    size_t n = size_t(static_cast<const unsigned char*>(z) - (b.data() + p));
    out.assign(reinterpret_cast<const char*>(b.data() + p), n);
    p += n + 1;
    return true;
  };
  ImageHeader h;
  h.format = ImageFormat::Exr;
  bool window = false;
  for (;;) {
    std::string name, type;
    if (!cstr(name)) return std::nullopt;
    if (name.empty()) break;  // end of the (first part's) header
    if (!cstr(type) || p + 4 > b.size()) return std::nullopt;
    int32_t size = le32(b.data() + p);
    p += 4;
    if (size < 0 || uint64_t(size) > b.size() - p) return std::nullopt;
    if (name == "dataWindow" && type == "box2i" && size == 16) {
      int64_t x0 = le32(b.data() + p), y0 = le32(b.data() + p + 4), x1 = le32(b.data() + p + 8), y1 = le32(b.data() + p + 12);
      if (!sideOk(x1 - x0 + 1) || !sideOk(y1 - y0 + 1)) return std::nullopt;
      h.width = int(x1 - x0 + 1);
      h.height = int(y1 - y0 + 1);
      window = true;
    }
    p += size_t(size);
  }
  if (!window) return std::nullopt;
  return h;
}

}  // namespace

std::optional<ImageHeader> readImageHeader(const std::string& path) {
  ImageFormat format = detectImageFormat(path);
  std::vector<unsigned char> b = readPrefix(path, format == ImageFormat::Exr ? (size_t(1) << 20) : (size_t(64) << 10));
  switch (format) {
    case ImageFormat::Png: return pngHeader(b);
    case ImageFormat::Pfm: return pfmHeader(b);
    case ImageFormat::Hdr: return hdrHeader(b);
    case ImageFormat::Exr: return exrHeader(b);
  }
  return std::nullopt;
}

}  // namespace tdpm::image
