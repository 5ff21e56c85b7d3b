// tests/test_image_formats.cpp — the readers `tdpm compare` uses besides
// OpenEXR's: PFM, Radiance HDR and PNG round trips of known images within
// each format's precision, endianness, row order and orientation by
// hand-made bytes, located errors, the content dispatcher; the EXR reader's
// limits (tdpm's largest output is admitted, lies about size are not) and
// channel sets; and `tdpm compare` across formats and with NaN/Inf.
#include <doctest/doctest.h>

#include <png.h>
#include <unistd.h>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
#include <Imath/half.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli_harness.h"
#include "core/error.h"
#include "image/exr.h"
#include "image/exr_header_check.h"
#include "image/hdr.h"
#include "image/pfm.h"
#include "image/png.h"
#include "image/read_image.h"

using namespace tdpm;
using namespace tdpm::image;

namespace {

struct Dir {
  std::string path = test::makeTempDir();
  ~Dir() { (void)std::system(("rm -rf '" + path + "'").c_str()); }
  std::string operator/(const std::string& name) const { return path + "/" + name; }
};

void writeBytes(const std::string& p, const std::string& bytes) {
  std::ofstream f(p, std::ios::binary);
  f << bytes;
}
std::string readBytes(const std::string& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

std::string floatBytes(std::initializer_list<float> values, bool littleEndian) {
  std::string out;
  for (float v : values) {
    uint32_t u;
    std::memcpy(&u, &v, 4);
    for (int k = 0; k < 4; ++k) out += char((u >> (8 * (littleEndian ? k : 3 - k))) & 0xff);
  }
  return out;
}

// Calls f, which must throw tdpm::Error whose message contains every part.
template <class F>
void checkError(F f, std::initializer_list<std::string> parts) {
  try {
    f();
    FAIL("no error thrown");
  } catch (const Error& e) {
    const std::string what = e.what();
    INFO(what);
    for (const std::string& p : parts) CHECK_MESSAGE(what.find(p) != std::string::npos, p);
  }
}

// A known image with distinct values in every pixel and channel, over the
// range references have (dark to bright).
ImageRgb knownImage(int w, int h) {
  ImageRgb im(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      im.at(x, y) = Rgb(0.01f + 0.5f * float(x), 0.25f * float(y) + 0.001f * float(x), 3.0f / float(1 + x + y));
  return im;
}

}  // namespace

// ---- PFM ----

TEST_CASE("pfm: writePfm round-trips exactly; rows bottom to top; both endiannesses; grey; scale") {
  Dir d;
  const ImageRgb im = knownImage(5, 3);
  writePfm(d / "a.pfm", im);
  const ImageRgb back = readPfm(d / "a.pfm");
  REQUIRE(back.width == 5);
  REQUIRE(back.height == 3);
  for (size_t i = 0; i < im.pixelCount(); ++i)
    for (int c = 0; c < 3; ++c) CHECK(back.pixels[i][c] == im.pixels[i][c]);
  // The written bytes: little-endian (scale -1), first stored row = bottom.
  const std::string bytes = readBytes(d / "a.pfm");
  CHECK(bytes.rfind("PF\n5 3\n-1\n", 0) == 0);
  CHECK(bytes.substr(10, 12) == floatBytes({im.at(0, 2).r, im.at(0, 2).g, im.at(0, 2).b}, true));

  // Hand-made 1x2 files: the first stored row is the bottom one.
  for (bool little : {true, false}) {
    CAPTURE(little);
    writeBytes(d / "h.pfm", std::string("PF\n1 2\n") + (little ? "-1.0" : "1.0") + "\n" +
                                floatBytes({1, 2, 3, 4, 5, 6}, little));
    ImageRgb h = readPfm(d / "h.pfm");
    CHECK(h.at(0, 1).r == 1);  // bottom
    CHECK(h.at(0, 1).b == 3);
    CHECK(h.at(0, 0).g == 5);  // top
  }
  // Grey, big-endian, |scale| 2 multiplies (as pbrt's reader does).
  writeBytes(d / "g.pfm", "Pf 2 1 2\n" + floatBytes({0.25f, -1.5f}, false));
  ImageRgb g = readPfm(d / "g.pfm");
  CHECK(g.at(0, 0).r == 0.5f);
  CHECK(g.at(0, 0).b == 0.5f);
  CHECK(g.at(1, 0).g == -3.0f);
}

TEST_CASE("pfm: bad files are located errors, sizes checked against the file first") {
  Dir d;
  const std::string p = d / "bad.pfm";
  auto expect = [&](const std::string& bytes, std::initializer_list<std::string> parts) {
    writeBytes(p, bytes);
    checkError([&] { readPfm(p); }, {p});
    checkError([&] { readPfm(p); }, parts);
  };
  const std::string px = floatBytes({1, 2, 3, 4, 5, 6}, true);
  expect("P6\n1 2\n255\n", {"not a PFM file"});
  expect("PF\n1 2\n-1\n" + px.substr(0, 20), {"needs 24 bytes", "has 20"});
  expect("PF\n1 2\n-1\n" + px + "x", {"needs 24 bytes", "has 25"});
  expect("PF\n70000 2\n-1\n" + px, {"70000x2", "65536"});
  expect("PF\n-1 2\n-1\n" + px, {"width", "'-1'"});
  expect("PF\n1 0\n-1\n" + px, {"height"});
  expect("PF\n1 2\n0\n" + px, {"scale", "'0'"});
  expect("PF\n1 2\nnan\n" + px, {"scale"});
  expect("PF\n1 2\n-1", {"scale"});
  // A declared 65536x65536 colour image in a few bytes: refused by its
  // size, nothing allocated.
  expect("PF\n65536 65536\n-1\n" + px, {"51539607552 bytes", "has 24"});
  checkError([&] { readPfm(d / "missing.pfm"); }, {"missing.pfm", "No such file"});
  checkError([&] { readPfm(d.path); }, {"directory"});
  checkError([&] { readPfm("/dev/zero"); }, {"/dev/zero", "not a regular file"});
}

// ---- Radiance HDR ----

TEST_CASE("hdr: RLE and flat scanlines round-trip within RGBE's 8-bit mantissa") {
  Dir d;
  // 40 wide: new-style RLE applies (8..32767); runs and literals both occur.
  ImageRgb im = knownImage(40, 3);
  for (int x = 10; x < 30; ++x) im.at(x, 1) = Rgb(0.75f, 0.5f, 0.25f);  // a run
  im.at(3, 2) = Rgb(0.0f);
  for (bool rle : {true, false}) {
    CAPTURE(rle);
    writeHdr(d / "a.hdr", im, rle);
    const ImageRgb back = readHdr(d / "a.hdr");
    REQUIRE(back.width == 40);
    REQUIRE(back.height == 3);
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 40; ++x) {
        const Rgb a = im.at(x, y), b = back.at(x, y);
        const float m = std::max(a.r, std::max(a.g, a.b));
        for (int c = 0; c < 3; ++c) CHECK(std::abs(b[c] - a[c]) <= m / 256.0f + 1e-30f);
      }
    CHECK(back.at(3, 2).r == 0.0f);
    CHECK(back.at(15, 1).r == doctest::Approx(0.75).epsilon(1.0 / 256));
  }
  // RLE really compressed the run, flat did not.
  writeHdr(d / "rle.hdr", im, true);
  writeHdr(d / "flat.hdr", im, false);
  CHECK(readBytes(d / "rle.hdr").size() < readBytes(d / "flat.hdr").size());
}

TEST_CASE("hdr: known RGBE values, orientations, old-style repeats, EXPOSURE") {
  Dir d;
  const std::string p = d / "o.hdr";
  // (128, 64, 32, 129): (m + 0.5) * 2^(129 - 136).
  const std::string A("\x80\x40\x20\x81", 4), B("\x40\x40\x40\x80", 4), C("\x10\x20\x30\x82", 4);
  const float ar = 128.5f / 128, ag = 64.5f / 128, bx = 64.5f / 256, cr = 16.5f / 64;
  auto file = [](const std::string& res, const std::string& px, const std::string& extra = "") {
    return "#?RADIANCE\n# comment\nFORMAT=32-bit_rle_rgbe\n" + extra + "\n" + res + "\n" + px;
  };
  writeBytes(p, file("-Y 1 +X 3", A + B + C));
  ImageRgb im = readHdr(p);
  REQUIRE(im.width == 3);
  CHECK(im.at(0, 0).r == ar);
  CHECK(im.at(0, 0).g == ag);
  CHECK(im.at(1, 0).b == bx);
  CHECK(im.at(2, 0).r == cr);
  // -X: right to left.
  writeBytes(p, file("-Y 1 -X 3", A + B + C));
  CHECK(readHdr(p).at(2, 0).r == ar);
  // +Y: bottom to top (first scanline is the bottom row).
  writeBytes(p, file("+Y 2 +X 1", A + C));
  im = readHdr(p);
  CHECK(im.at(0, 1).r == ar);
  CHECK(im.at(0, 0).r == cr);
  // Transposed: scanlines are columns ("+X 2 -Y 3": 2 columns of 3, left first).
  writeBytes(p, file("+X 2 -Y 3", A + B + C + C + B + A));
  im = readHdr(p);
  REQUIRE(im.width == 2);
  REQUIRE(im.height == 3);
  CHECK(im.at(0, 0).r == ar);
  CHECK(im.at(0, 2).r == cr);
  CHECK(im.at(1, 2).r == ar);
  // Old-style repeat (1, 1, 1, 2): the previous pixel twice more.
  writeBytes(p, file("-Y 1 +X 4", A + std::string("\x01\x01\x01\x02", 4) + C));
  im = readHdr(p);
  CHECK(im.at(2, 0).r == ar);
  CHECK(im.at(3, 0).r == cr);
  // EXPOSURE lines multiply; pixels are divided by the product.
  writeBytes(p, file("-Y 1 +X 1", A, "EXPOSURE=2\nEXPOSURE=0.5e1\n"));
  CHECK(readHdr(p).at(0, 0).r == doctest::Approx(ar / 10));
  // "#?RGBE" is accepted as a first line too.
  writeBytes(p, "#?RGBE\n\n-Y 1 +X 1\n" + A);
  CHECK(readHdr(p).at(0, 0).r == ar);
}

TEST_CASE("hdr: bad files are located errors") {
  Dir d;
  const std::string p = d / "bad.hdr";
  auto expect = [&](const std::string& bytes, std::initializer_list<std::string> parts) {
    writeBytes(p, bytes);
    checkError([&] { readHdr(p); }, {p});
    checkError([&] { readHdr(p); }, parts);
  };
  const std::string A("\x80\x40\x20\x81", 4);
  expect("P6\n", {"not a Radiance HDR file"});
  expect("#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 1\n" + A, {"line 2", "XYZ"});
  expect("#?RADIANCE\nFORMAT=bogus\n\n-Y 1 +X 1\n" + A, {"line 2", "unknown FORMAT 'bogus'"});
  expect("#?RADIANCE\nEXPOSURE=-1\n\n-Y 1 +X 1\n" + A, {"line 2", "EXPOSURE"});
  expect("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n", {"header does not end"});
  expect("#?RADIANCE\n\n-Y 1 +Y 1\n" + A, {"line 3", "resolution", "'-Y 1 +Y 1'"});
  expect("#?RADIANCE\n\n-Y 1 +X 70000\n" + A, {"line 3", "resolution"});
  expect("#?RADIANCE\n\n-Y 2 +X 2\n" + A + A + A + "\x80", {"scanline 1 of 2", "ends"});
  expect("#?RADIANCE\n\n-Y 1 +X 1\n" + A + A, {"data after"});
  // New-style RLE: a run longer than the scanline, a zero-length run, a
  // length header that disagrees with the width.
  const std::string rleHead("\x02\x02\x00\x08", 4);
  expect("#?RADIANCE\n\n-Y 1 +X 8\n" + rleHead + std::string("\x89\x05", 2), {"scanline 0", "passes the end"});
  expect("#?RADIANCE\n\n-Y 1 +X 8\n" + rleHead + std::string("\x00", 1) + std::string(40, 'a'), {"length 0"});
  expect("#?RADIANCE\n\n-Y 1 +X 9\n" + rleHead + std::string(40, 'a'), {"says 8 pixels", "the image 9"});
  expect("#?RADIANCE\n\n-Y 1 +X 3\n" + std::string("\x01\x01\x01\x01", 4) + A + A, {"before the first pixel"});
  // 65536 scanlines declared in a few bytes: refused before decoding.
  expect("#?RADIANCE\n\n-Y 65536 +X 65536\n" + A, {"65536 scanlines", "at least 262144 bytes"});
}

// ---- PNG ----

namespace {

void writePngRaw(const std::string& path, png_uint_32 format, int w, int h, const void* data,
                 const void* colormap = nullptr, int colormapEntries = 0) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = png_uint_32(w);
  png.height = png_uint_32(h);
  png.format = format;
  png.colormap_entries = png_uint_32(colormapEntries);
  REQUIRE(png_image_write_to_file(&png, path.c_str(), 0, data, 0, colormap) != 0);
}

}  // namespace

TEST_CASE("png: 8-bit grey/RGB/RGBA/palette decode sRGB to linear; 16-bit; the preview round-trips") {
  Dir d;
  CHECK(srgbDecode(0.0f) == 0.0f);
  CHECK(srgbDecode(1.0f) == doctest::Approx(1.0));
  CHECK(srgbDecode(0.5f) == doctest::Approx(0.21404).epsilon(1e-4));  // IEC 61966-2-1
  CHECK(srgbDecode(0.04f) == doctest::Approx(0.04 / 12.92));

  // RGB, 2x1: codes (0, 128, 255), (10, 20, 30); the first row is the top.
  const uint8_t rgb[] = {0, 128, 255, 10, 20, 30, 1, 2, 3, 4, 5, 6};
  writePngRaw(d / "rgb.png", PNG_FORMAT_RGB, 2, 2, rgb);
  ImageRgb im = readPngLinear(d / "rgb.png");
  REQUIRE(im.width == 2);
  CHECK(im.at(0, 0).r == 0.0f);
  CHECK(im.at(0, 0).g == doctest::Approx(srgbDecode(128 / 255.0f)));
  CHECK(im.at(0, 0).b == doctest::Approx(1.0));
  CHECK(im.at(1, 0).b == doctest::Approx(srgbDecode(30 / 255.0f)));
  CHECK(im.at(1, 1).g == doctest::Approx(srgbDecode(5 / 255.0f)));
  // Grey.
  const uint8_t grey[] = {64, 200};
  writePngRaw(d / "grey.png", PNG_FORMAT_GRAY, 2, 1, grey);
  im = readPngLinear(d / "grey.png");
  CHECK(im.at(0, 0).r == doctest::Approx(srgbDecode(64 / 255.0f)));
  CHECK(im.at(1, 0).b == doctest::Approx(srgbDecode(200 / 255.0f)));
  // RGBA: alpha is not applied (straight colour), even at alpha 0.
  const uint8_t rgba[] = {100, 150, 200, 128, 50, 60, 70, 0};
  writePngRaw(d / "rgba.png", PNG_FORMAT_RGBA, 2, 1, rgba);
  im = readPngLinear(d / "rgba.png");
  CHECK(im.at(0, 0).g == doctest::Approx(srgbDecode(150 / 255.0f)));
  CHECK(im.at(1, 0).r == doctest::Approx(srgbDecode(50 / 255.0f)));
  // Palette.
  const uint8_t palette[] = {255, 0, 0, 0, 90, 255};
  const uint8_t index[] = {1, 0, 1};
  writePngRaw(d / "pal.png", PNG_FORMAT_RGB_COLORMAP, 3, 1, index, palette, 2);
  im = readPngLinear(d / "pal.png");
  CHECK(im.at(0, 0).r == 0.0f);
  CHECK(im.at(0, 0).g == doctest::Approx(srgbDecode(90 / 255.0f)));
  CHECK(im.at(1, 0).r == doctest::Approx(1.0));
  // 16-bit linear (libpng writes linear 16-bit data with gAMA 1.0).
  const uint16_t lin[] = {0, 32768, 65535, 6554, 13107, 19661};
  writePngRaw(d / "16.png", PNG_FORMAT_LINEAR_RGB, 2, 1, lin);
  im = readPngLinear(d / "16.png");
  CHECK(im.at(0, 0).g == doctest::Approx(32768 / 65535.0).epsilon(1e-4));
  CHECK(im.at(1, 0).r == doctest::Approx(0.1).epsilon(1e-4));
  CHECK(im.at(1, 0).b == doctest::Approx(0.3).epsilon(1e-4));

  // tdpm's own preview: linear -> sRGB 8-bit -> linear, within one code step.
  ImageRgb src = knownImage(6, 4);
  for (Rgb& p : src.pixels) p = Rgb(std::min(p.r, 1.0f), std::min(p.g, 1.0f), std::min(p.b, 1.0f));
  writePngPreview(d / "preview.png", src, 0.0f);
  im = readPngLinear(d / "preview.png");
  for (size_t i = 0; i < src.pixelCount(); ++i)
    for (int c = 0; c < 3; ++c) {
      const float v = src.pixels[i][c];
      const int code = toSrgb8(v);
      CHECK(im.pixels[i][c] == doctest::Approx(srgbDecode(code / 255.0f)));
      // ...which is the nearest sRGB level: half a code step in sRGB space.
      CHECK(std::abs(srgbEncode(im.pixels[i][c]) - srgbEncode(v)) <= 0.5f / 255 + 1e-6f);
    }
}

TEST_CASE("png: damaged files are located errors") {
  Dir d;
  const uint8_t rgb[12] = {};
  writePngRaw(d / "ok.png", PNG_FORMAT_RGB, 2, 2, rgb);
  const std::string bytes = readBytes(d / "ok.png");
  writeBytes(d / "cut.png", bytes.substr(0, bytes.size() / 2));
  checkError([&] { readPngLinear(d / "cut.png"); }, {d / "cut.png", "cannot read PNG"});
  // A 60000x60000 header in a tiny file (CRC fixed up so libpng accepts it).
  std::string big = bytes;
  const uint32_t side = 60000;
  for (int at : {16, 20})
    for (int k = 0; k < 4; ++k) big[size_t(at + k)] = char((side >> (8 * (3 - k))) & 0xff);
  uint32_t crc = 0xffffffffu;  // PNG's CRC-32 over the chunk type and data
  for (size_t i = 12; i < 29; ++i) {
    crc ^= uint8_t(big[i]);
    for (int b = 0; b < 8; ++b) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  crc ^= 0xffffffffu;
  for (int k = 0; k < 4; ++k) big[size_t(29 + k)] = char((crc >> (8 * (3 - k))) & 0xff);
  writeBytes(d / "big.png", big);
  checkError([&] { readPngLinear(d / "big.png"); }, {d / "big.png", "60000x60000", "cannot be held"});
}

// ---- dispatcher ----

TEST_CASE("read_image: format by content; a mismatching extension or unknown content is an error") {
  Dir d;
  const ImageRgb im = knownImage(4, 2);
  writePfm(d / "a.pfm", im);
  writeHdr(d / "a.hdr", im);
  writePngPreview(d / "a.png", im, 0.0f);
  ExrFile exr;
  exr.color = im;
  writeExr(d / "a.exr", exr);
  CHECK(detectImageFormat(d / "a.pfm") == ImageFormat::Pfm);
  CHECK(detectImageFormat(d / "a.hdr") == ImageFormat::Hdr);
  CHECK(detectImageFormat(d / "a.png") == ImageFormat::Png);
  CHECK(detectImageFormat(d / "a.exr") == ImageFormat::Exr);
  for (const char* name : {"a.pfm", "a.exr"}) {
    LoadedImage l = readImage(d / name);
    for (size_t i = 0; i < im.pixelCount(); ++i) CHECK(l.color.pixels[i].g == im.pixels[i].g);
  }
  // Unknown extension: the content decides.
  writeBytes(d / "ref.bin", readBytes(d / "a.pfm"));
  CHECK(readImage(d / "ref.bin").format == ImageFormat::Pfm);
  writeBytes(d / "wrong.hdr", readBytes(d / "a.pfm"));
  checkError([&] { readImage(d / "wrong.hdr"); }, {"wrong.hdr", "name says Radiance HDR", "content is PFM"});
  writeBytes(d / "text.pfm", "hello\n");
  checkError([&] { readImage(d / "text.pfm"); }, {"text.pfm", "not a PFM file", "tdpm reads OpenEXR, PFM"});
  writeBytes(d / "empty", "");
  checkError([&] { readImage(d / "empty"); }, {"empty", "not an image", "the file is empty"});
  checkError([&] { readImage("/dev/zero"); }, {"not a regular file"});
  checkError([&] { readImage(d.path); }, {"directory"});
}

// ---- OpenEXR limits and channels (issue 11, items 16 and 17) ----

namespace {

// A constant HALF image written from one row repeated (y stride 0: no
// image-sized buffer), RLE compressed: about 1 byte in 64 of its size.
void writeConstantExr(const std::string& path, int w, int h, const std::vector<const char*>& names, float value) {
  Imf::Header header(w, h);
  header.compression() = Imf::RLE_COMPRESSION;
  Imf::FrameBuffer fb;
  std::vector<half> row(static_cast<size_t>(w), half(value));
  for (const char* n : names) {
    header.channels().insert(n, Imf::Channel(Imf::HALF));
    fb.insert(n, Imf::Slice(Imf::HALF, reinterpret_cast<char*>(row.data()), sizeof(half), 0));
  }
  Imf::OutputFile out(path.c_str(), header);
  out.setFrameBuffer(fb);
  out.writePixels(h);
}

}  // namespace

TEST_CASE("exr: tdpm's largest outputs are admitted; the header check still bounds allocation by file size") {
  Dir d;
  // Issue 11 item 16: 65536x2049 (2^27 + 65536 pixels, over the old limit)
  // is within render's 65536-per-side resolution.
  const std::string big = d / "big.exr";
  writeConstantExr(big, 65536, 2049, {"Y"}, 0.5f);
  {
    std::FILE* f = std::fopen(big.c_str(), "rb");
    REQUIRE(f);
    CHECK(checkExrHeader(f) == "");
    std::fclose(f);
  }
  ExrFile e = readExr(big);
  REQUIRE(e.color.width == 65536);
  REQUIRE(e.color.height == 2049);
  CHECK(e.color.at(0, 0).r == 0.5f);
  CHECK(e.color.at(65535, 2048).b == 0.5f);
  CHECK(e.color.at(31000, 1000).g == 0.5f);
  e = ExrFile();  // 1.6 GB back before the next step

  // The same header claiming 65536 x 65536 in this file's bytes: more than
  // RLE can hold, refused before OpenEXR or tdpm allocate.
  std::string bytes = readBytes(big);
  const std::string window("dataWindow\0box2i\0", 17);
  const size_t at = bytes.find(window);
  REQUIRE(at != std::string::npos);
  const size_t maxY = at + window.size() + 4 + 12;
  for (int k = 0; k < 4; ++k) bytes[maxY + size_t(k)] = char((65535u >> (8 * k)) & 0xff);
  writeBytes(d / "lie.exr", bytes);
  checkError([&] { readExr(d / "lie.exr"); },
             {"lie.exr", "data window 65536x65536", "RLE compression", "at most 64 to 1"});
  // Over the per-side limit tdpm writes.
  CHECK(exrMaxCompressionRatio(1) == 64);
  CHECK(exrMaxCompressionRatio(10) == 0);
}

TEST_CASE("exr: channel sets that are not colour or grey are refused, naming what was found") {
  Dir d;
  writeConstantExr(d / "xyz.exr", 4, 2, {"X", "Y", "Z"}, 1.0f);
  checkError([&] { readExr(d / "xyz.exr"); }, {"xyz.exr", "channels not understood", "X, Y, Z", "R, G, B"});
  writeConstantExr(d / "rg.exr", 4, 2, {"R", "G"}, 1.0f);
  checkError([&] { readExr(d / "rg.exr"); }, {"rg.exr", "G, R"});
  writeConstantExr(d / "yc.exr", 4, 2, {"Y", "RY", "BY"}, 1.0f);
  checkError([&] { readExr(d / "yc.exr"); }, {"BY, RY, Y"});
  writeConstantExr(d / "depth.exr", 4, 2, {"depth"}, 1.0f);
  checkError([&] { readExr(d / "depth.exr"); }, {"depth"});
  // Y with A and a depth channel Z is grey.
  writeConstantExr(d / "ya.exr", 4, 2, {"Y", "A", "Z"}, 0.25f);
  ExrFile f = readExr(d / "ya.exr");
  CHECK(f.color.at(3, 1).g == 0.25f);
  CHECK(f.findChannel("Z") != nullptr);
}

// ---- tdpm compare across formats, and NaN/Inf ----

TEST_CASE("cli compare: any two formats; NaN/Inf refused unless --allow-nonfinite") {
  Dir d;
  ImageRgb im = knownImage(16, 4);
  writePfm(d / "a.pfm", im);
  ExrFile exr;
  exr.color = im;
  writeExr(d / "a.exr", exr);
  writeHdr(d / "a.hdr", im);
  auto q = [&](const std::string& n) { return " '" + (d / n) + "'"; };

  auto r = test::runTdpm("compare" + q("a.pfm") + q("a.exr") + " --json");
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  nlohmann::json j = nlohmann::json::parse(r.output);
  CHECK(j["rmse"]["overall"].get<double>() == 0.0);
  CHECK(j["test_format"] == "PFM");
  CHECK(j["reference_format"] == "OpenEXR");
  // HDR against the exact image: only RGBE's quantisation, under 2^-8 of
  // the brightest channel per value.
  r = test::runTdpm("compare" + q("a.hdr") + q("a.pfm") + " --json");
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  j = nlohmann::json::parse(r.output);
  CHECK(j["max_abs_error"]["overall"].get<double>() > 0.0);
  CHECK(j["max_abs_error"]["overall"].get<double>() <= 7.51 / 256);  // brightest value: 7.51 (x = 15)

  // An Inf where the reference is 0 is not "no error".
  ImageRgb bad = im;
  bad.at(5, 2).g = std::numeric_limits<float>::infinity();
  bad.at(6, 3).r = std::numeric_limits<float>::quiet_NaN();
  writePfm(d / "bad.pfm", bad);
  r = test::runTdpm("compare" + q("bad.pfm") + q("a.exr"));
  CHECK(r.exitCode == 1);
  for (const char* w : {"test image", "bad.pfm", "2 NaN or infinite values", "pixel (5, 2) channel G", "--allow-nonfinite"})
    CHECK_MESSAGE(r.output.find(w) != std::string::npos, w);
  r = test::runTdpm("compare" + q("a.exr") + q("bad.pfm"));
  CHECK(r.exitCode == 1);
  CHECK(r.output.find("reference image") != std::string::npos);
  // Outside the crop they do not matter.
  r = test::runTdpm("compare" + q("bad.pfm") + q("a.exr") + " --crop 0,0,4,2");
  CHECK(r.exitCode == 0);
  r = test::runTdpm("compare" + q("bad.pfm") + q("a.exr") + " --allow-nonfinite --json");
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  j = nlohmann::json::parse(r.output.substr(r.output.find('{')));
  CHECK(j["nonfinite_values"]["test"] == 2);
  CHECK(j["nonfinite_values"]["reference"] == 0);
  auto help = test::runTdpm("compare --help");
  CHECK(help.output.find("--allow-nonfinite") != std::string::npos);
  CHECK(help.output.find("PFM") != std::string::npos);
}
