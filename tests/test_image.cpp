// tests/test_image.cpp — image/ (EXR and PNG I/O, preview paths) and
// core/atomic_file: bit-exact round trips, errors that name the file, no
// half-written output, and an independent reader (OpenImageIO's oiiotool)
// agreeing with ours about what we wrote.
#include <doctest/doctest.h>

#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
#include <Imath/half.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/rng.h"
#include "image/exr.h"
#include "image/png.h"

using namespace tdpm;
using namespace tdpm::image;

namespace {

// A fresh directory per test case, removed (with its files) afterwards.
struct TempDir {
  std::string path;
  TempDir() {
    static int counter = 0;
    const char* base = std::getenv("TMPDIR");
    path = std::string(base && *base ? base : "/tmp") + "/tdpm_test_image." + std::to_string(::getpid()) + "." +
           std::to_string(counter++);
    std::string cmd = "rm -rf '" + path + "'";
    REQUIRE(std::system(cmd.c_str()) == 0);
    REQUIRE(::mkdir(path.c_str(), 0755) == 0);
  }
  ~TempDir() {
    std::string cmd = "rm -rf '" + path + "'";
    (void)std::system(cmd.c_str());
  }
  std::string operator/(const std::string& name) const { return path + "/" + name; }
  std::vector<std::string> list() const {
    std::vector<std::string> names;
    if (DIR* d = ::opendir(path.c_str())) {
      while (dirent* e = ::readdir(d))
        if (std::strcmp(e->d_name, ".") != 0 && std::strcmp(e->d_name, "..") != 0) names.push_back(e->d_name);
      ::closedir(d);
    }
    return names;
  }
};

bool exists(const std::string& p) {
  struct stat st;
  return ::stat(p.c_str(), &st) == 0;
}

std::string readBytes(const std::string& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

void writeBytes(const std::string& p, const std::string& bytes) {
  std::ofstream f(p, std::ios::binary);
  f << bytes;
}

bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; }

// A test image with every kind of float the renderer might produce:
// ordinary values, zero, -0, denormals, huge, inf, NaN.
ExrFile makeFile(int w, int h, uint64_t seed) {
  ExrFile f;
  f.color = ImageRgb(w, h);
  Rng rng(seed);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      f.color.at(x, y) = Rgb(rng.uniform() * 10.0f, float(x) - 0.5f * float(y), rng.uniform() * 1e-3f);
  const float special[] = {0.0f, -0.0f, std::numeric_limits<float>::denorm_min(), 3.0e38f,
                           std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN()};
  for (size_t i = 0; i < f.color.pixels.size() * 3 && i < 6; ++i) f.color.pixels[i / 3][int(i % 3)] = special[i];
  Channel spp{"spp", std::vector<float>(f.color.pixelCount())};
  Channel var{"variance.R", std::vector<float>(f.color.pixelCount())};
  for (size_t i = 0; i < spp.values.size(); ++i) {
    spp.values[i] = float(16 + i);
    var.values[i] = rng.uniform() * 0.01f;
  }
  f.extra = {spp, var};
  f.metadata = {{"tdpm/scene", "scenes/glass-ball.json"}, {"tdpm/method", "pathtrace"},
                {"tdpm/spp", "64"},                      {"tdpm/seed", "7"},
                {"tdpm/render_seconds", "1.25"}};
  return f;
}

void checkSame(const ExrFile& a, const ExrFile& b) {
  REQUIRE(a.color.width == b.color.width);
  REQUIRE(a.color.height == b.color.height);
  for (size_t i = 0; i < a.color.pixelCount(); ++i)
    for (int c = 0; c < 3; ++c) REQUIRE(sameBits(a.color.pixels[i][c], b.color.pixels[i][c]));
  REQUIRE(a.extra.size() == b.extra.size());
  for (const Channel& ca : a.extra) {
    const Channel* cb = b.findChannel(ca.name);
    REQUIRE(cb != nullptr);
    REQUIRE(cb->values.size() == ca.values.size());
    for (size_t i = 0; i < ca.values.size(); ++i) REQUIRE(sameBits(ca.values[i], cb->values[i]));
  }
  CHECK(a.metadata == b.metadata);
}

// Runs a command, returns its stdout (stderr discarded) with runs of spaces
// collapsed to one (oiiotool pads "   3 x    2" into columns).
std::string runCapture(const std::string& cmd) {
  std::string out;
  if (FILE* p = ::popen((cmd + " 2>/dev/null").c_str(), "r")) {
    char buf[4096];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
    ::pclose(p);
  }
  std::string collapsed;
  for (char c : out)
    if (!(c == ' ' && !collapsed.empty() && collapsed.back() == ' ')) collapsed += c;
  return collapsed;
}

bool haveOiiotool() { return std::system("command -v oiiotool >/dev/null 2>&1") == 0; }

// Expects f() to throw tdpm::Error whose message contains every needle.
template <class F>
void checkError(F&& f, std::initializer_list<std::string> needles) {
  try {
    f();
    FAIL("expected tdpm::Error");
  } catch (const Error& e) {
    std::string msg = e.what();
    for (const std::string& n : needles) {
      INFO("message: " << msg << " | expected to contain: " << n);
      CHECK(msg.find(n) != std::string::npos);
    }
  }
}

}  // namespace

// ---- EXR round trips ----

TEST_CASE("exr: round trip is bit-exact for RGB, extra channels and metadata") {
  TempDir dir;
  for (auto [w, h] : {std::pair{7, 5}, std::pair{1, 1}, std::pair{1, 9}, std::pair{33, 2}}) {
    CAPTURE(w);
    CAPTURE(h);
    ExrFile f = makeFile(w, h, uint64_t(w * 100 + h));
    const std::string path = dir / ("rt_" + std::to_string(w) + "x" + std::to_string(h) + ".exr");
    writeExr(path, f);
    checkSame(f, readExr(path));
  }
  // Only the outputs remain: no temporary files left behind.
  for (const std::string& name : dir.list()) CHECK(name.find(".tmp.") == std::string::npos);
  CHECK(dir.list().size() == 4);
}

TEST_CASE("exr: overwriting replaces the previous file completely") {
  TempDir dir;
  const std::string path = dir / "out.exr";
  writeExr(path, makeFile(40, 30, 1));
  ExrFile small = makeFile(2, 3, 2);
  small.extra.clear();
  small.metadata = {{"tdpm/method", "time"}};
  writeExr(path, small);
  checkSame(small, readExr(path));
  CHECK(dir.list().size() == 1);
}

TEST_CASE("exr: reads Y-only images as grey, HALF channels, and an offset data window") {
  TempDir dir;
  const std::string path = dir / "grey.exr";
  // Written with OpenEXR directly, as another program would: data window
  // (10,20)-(12,21), i.e. 3x2, luminance and a HALF depth channel.
  const Imath::Box2i dw(Imath::V2i(10, 20), Imath::V2i(12, 21));
  std::vector<float> y = {0.0f, 0.25f, 0.5f, 1.0f, 2.0f, 4.0f};
  std::vector<Imath::half> depth;
  for (int i = 0; i < 6; ++i) depth.push_back(Imath::half(float(i) + 0.5f));
  {
    Imf::Header header(Imath::Box2i(Imath::V2i(0, 0), Imath::V2i(20, 30)), dw);
    header.channels().insert("Y", Imf::Channel(Imf::FLOAT));
    header.channels().insert("depth", Imf::Channel(Imf::HALF));
    Imf::FrameBuffer fb;
    fb.insert("Y", Imf::Slice::Make(Imf::FLOAT, y.data(), dw));
    fb.insert("depth", Imf::Slice::Make(Imf::HALF, depth.data(), dw));
    Imf::OutputFile out(path.c_str(), header);
    out.setFrameBuffer(fb);
    out.writePixels(2);
  }
  ExrFile f = readExr(path);
  REQUIRE(f.color.width == 3);
  REQUIRE(f.color.height == 2);
  for (int i = 0; i < 6; ++i) {
    const Rgb& p = f.color.pixels[size_t(i)];
    CHECK(p.r == y[size_t(i)]);
    CHECK(p.g == y[size_t(i)]);
    CHECK(p.b == y[size_t(i)]);
  }
  const Channel* d = f.findChannel("depth");
  REQUIRE(d != nullptr);
  CHECK(f.extra.size() == 1);
  for (int i = 0; i < 6; ++i) CHECK(d->values[size_t(i)] == float(i) + 0.5f);
  CHECK(f.metadata.empty());
}

// ---- EXR errors ----

TEST_CASE("exr: missing, non-EXR, truncated and corrupt files are tdpm::Error naming the path") {
  TempDir dir;
  const std::string missing = dir / "nope.exr";
  checkError([&] { readExr(missing); }, {missing, "No such file or directory"});

  checkError([&] { readExr(dir.path); }, {dir.path, "directory"});

  const std::string text = dir / "text.exr";
  writeBytes(text, "this is not an image\n");
  checkError([&] { readExr(text); }, {text, "not an OpenEXR file"});

  const std::string empty = dir / "empty.exr";
  writeBytes(empty, "");
  checkError([&] { readExr(empty); }, {empty, "not an OpenEXR file"});

  // A real EXR cut short: in the pixel data, and inside the header.
  const std::string good = dir / "good.exr";
  writeExr(good, makeFile(64, 48, 3));
  const std::string bytes = readBytes(good);
  for (size_t keep : {bytes.size() / 2, bytes.size() - 10, size_t(40), size_t(8)}) {
    CAPTURE(keep);
    const std::string cut = dir / ("cut" + std::to_string(keep) + ".exr");
    writeBytes(cut, bytes.substr(0, keep));
    checkError([&] { readExr(cut); }, {cut});
  }

  // Corrupted bytes anywhere: either a clean read or tdpm::Error, never a
  // crash or a foreign exception (OpenEXR's Iex types must not escape).
  Rng rng(11);
  int errors = 0;
  const std::string bad = dir / "bad.exr";
  for (int trial = 0; trial < 300; ++trial) {
    std::string mutated = bytes;
    const int flips = 1 + int(rng.below(4));
    for (int k = 0; k < flips; ++k) mutated[rng.below(uint32_t(mutated.size()))] ^= char(1u << rng.below(8));
    writeBytes(bad, mutated);
    try {
      ExrFile f = readExr(bad);
      CHECK(f.color.pixels.size() == f.color.pixelCount());
    } catch (const Error& e) {
      ++errors;
      CHECK(std::string(e.what()).find(bad) == 0);
    }
  }
  MESSAGE(errors << " of 300 corrupted files were rejected with tdpm::Error");
}

// Hand-built headers: each one made OpenEXR 3.1 allocate far more than the
// file holds (0.1-16 GB from a few hundred bytes; fuzz_exr found the first
// two). image/exr_header_check must reject them before OpenEXR sees them,
// with a message saying which attribute is wrong.
namespace {

struct HeaderBytes {
  std::string bytes = std::string("\x76\x2f\x31\x01\x02\x00\x00\x00", 8);
  HeaderBytes& attr(const std::string& name, const std::string& type, const std::string& value,
                    int64_t declared = -1) {
    const int32_t size = int32_t(declared >= 0 ? declared : int64_t(value.size()));
    bytes += name + '\0' + type + '\0';
    for (int i = 0; i < 4; ++i) bytes += char((uint32_t(size) >> (8 * i)) & 0xff);
    bytes += value;
    return *this;
  }
  static std::string i32s(std::initializer_list<int32_t> values) {
    std::string out;
    for (int32_t v : values)
      for (int i = 0; i < 4; ++i) out += char((uint32_t(v) >> (8 * i)) & 0xff);
    return out;
  }
  static std::string channel(const std::string& name) {  // FLOAT, sampling 1x1
    return name + '\0' + i32s({2}) + std::string(4, '\0') + i32s({1, 1});
  }
  // The attributes every scanline image needs, for a w x h data window.
  HeaderBytes& image(int32_t w, int32_t h) {
    attr("channels", "chlist", channel("R") + channel("G") + channel("B") + '\0');
    attr("compression", "compression", std::string(1, '\0'));
    attr("dataWindow", "box2i", i32s({0, 0, w - 1, h - 1}));
    attr("displayWindow", "box2i", i32s({0, 0, w - 1, h - 1}));
    attr("lineOrder", "lineOrder", std::string(1, '\0'));
    attr("pixelAspectRatio", "float", i32s({0x3f800000}));
    attr("screenWindowCenter", "v2f", std::string(8, '\0'));
    return attr("screenWindowWidth", "float", i32s({0x3f800000}));
  }
  std::string end() const { return bytes + '\0' + std::string(64, '\0'); }
};

}  // namespace

TEST_CASE("exr: headers whose sizes lie are rejected before OpenEXR allocates") {
  TempDir dir;
  const std::string path = dir / "lie.exr";
  auto expect = [&](const std::string& bytes, std::initializer_list<std::string> parts) {
    writeBytes(path, bytes);
    checkError([&] { readExr(path); }, {path, "corrupt OpenEXR header"});
    checkError([&] { readExr(path); }, parts);
  };
  using H = HeaderBytes;

  // The well-formed base reads past the header check (and then fails on the
  // missing pixel data, which is a different error).
  writeBytes(path, H().image(4, 3).end());
  try {
    readExr(path);
    FAIL("a header without pixel data was read");
  } catch (const Error& e) {
    CHECK(std::string(e.what()).find("corrupt OpenEXR header") == std::string::npos);
  }

  // A string claiming more bytes than the file has (OpenEXR allocated it).
  expect(H().image(4, 3).attr("owner", "string", "me", 1900000000).end(), {"'owner'", "claims 1900000000"});
  // A channel list whose declared size disagrees with its channels: OpenEXR
  // reads the channels, then takes later bytes as the next attribute's size.
  expect(H().attr("channels", "chlist", H::channel("R") + '\0', 156).image(4, 3).end(),
         {"'channels'", "declares 156", "take 19"});
  // A fixed-size type with a wrong declared size.
  expect(H().attr("dataWindow", "box2i", H::i32s({0, 0, 3}), 12).image(4, 3).end(),
         {"'dataWindow'", "declares 12", "has 16"});
  // A preview image whose width x height OpenEXR would allocate.
  expect(H().image(4, 3).attr("preview", "preview", H::i32s({60000, 60000}), 8).end(),
         {"'preview'", "60000x60000"});
  // A data window of 2^32 pixels, and a tiling of 2^27 tiles of 1x1.
  expect(H().image(65536, 65536).end(), {"data window 65536x65536"});
  // (A repeated attribute replaces the earlier one, in OpenEXR too.)
  expect(H().image(4, 3)
             .attr("dataWindow", "box2i", H::i32s({-2147483647 - 1, -2147483647 - 1, 2147483647, 2147483647}))
             .end(),
         {"data window 4294967296x4294967296"});
  expect(H().image(16384, 8192).attr("tiles", "tiledesc", H::i32s({1, 1}) + '\0').end(), {"134217728 tiles"});
  // The chunk count that sizes the offset table of a part of unknown type.
  expect(H().image(4, 3).attr("chunkCount", "int", H::i32s({2000000000})).end(), {"'chunkCount'", "2000000000"});
}

// ---- atomic output ----

TEST_CASE("atomic: failures leave neither a target nor a temporary file") {
  TempDir dir;
  // Directory missing: the error names the path and the OS reason.
  const std::string inMissing = dir / "no/such/dir/out.exr";
  checkError([&] { writeExr(inMissing, makeFile(4, 4, 1)); }, {inMissing, "No such file or directory"});
  checkError([&] { writePngPreview(dir / "no/out.png", makeFile(4, 4, 1).color, 0.0f); },
             {dir / "no/out.png", "No such file or directory"});
  CHECK(!exists(dir / "no"));
  CHECK(dir.list().empty());

  // The target is a directory.
  ::mkdir((dir / "sub").c_str(), 0755);
  checkError([&] { writeExr(dir / "sub", makeFile(2, 2, 1)); }, {dir / "sub", "directory"});

  // A failure inside OpenEXR after the temp file exists (a metadata key that
  // clashes with a standard attribute of another type): the previous file
  // stays untouched, no temp remains.
  const std::string target = dir / "keep.exr";
  writeBytes(target, "previous contents");
  ExrFile f = makeFile(3, 3, 2);
  f.metadata["compression"] = "zip";
  checkError([&] { writeExr(target, f); }, {target});
  CHECK(readBytes(target) == "previous contents");
  CHECK(dir.list().size() == 2);  // sub/ and keep.exr

  // Unwritable directory (meaningless as root, who may write anywhere).
  if (::geteuid() != 0) {
    const std::string ro = dir / "ro";
    ::mkdir(ro.c_str(), 0555);
    checkError([&] { writeExr(ro + "/x.exr", makeFile(2, 2, 1)); }, {ro + "/x.exr", "Permission denied"});
    ::chmod(ro.c_str(), 0755);
  }
}

TEST_CASE("atomic: uncommitted files vanish, commit replaces, temp names are unique") {
  TempDir dir;
  const std::string target = dir / "a.txt";
  {
    AtomicFile a(target), b(target);
    CHECK(a.tempPath() != b.tempPath());
    CHECK(a.tempPath().rfind(dir / ".a.txt.tmp.", 0) == 0);
    CHECK(exists(a.tempPath()));
    writeBytes(a.tempPath(), "half");
    CHECK(!exists(target));
  }
  CHECK(dir.list().empty());

  writeTextFileAtomic(target, "one");
  writeTextFileAtomic(target, "two");
  CHECK(readBytes(target) == "two");
  CHECK(dir.list().size() == 1);

  // Relative path without a directory part works too (temp beside it).
  const std::string cwdTarget = "tdpm_test_atomic_" + std::to_string(::getpid()) + ".txt";
  writeTextFileAtomic(cwdTarget, "x");
  CHECK(readBytes(cwdTarget) == "x");
  std::remove(cwdTarget.c_str());
}

// ---- the independent reader ----

TEST_CASE("exr: OpenImageIO's oiiotool reads what we write") {
  if (!haveOiiotool()) {
    MESSAGE("oiiotool not on PATH (Debian: openimageio-tools): independent check skipped");
    return;
  }
  TempDir dir;
  const std::string path = dir / "oiio.exr";
  ExrFile f;
  f.color = ImageRgb(3, 2);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x) f.color.at(x, y) = Rgb(0.25f * float(x), float(y) + 0.5f, float(x + 3 * y) * 10.0f);
  f.extra = {Channel{"spp", {1, 2, 3, 4, 5, 6}}};
  f.metadata = {{"tdpm/scene", "scenes/glass-ball.json"}, {"tdpm/method", "pathtrace"}};
  writeExr(path, f);

  const std::string info = runCapture("oiiotool --info -v '" + path + "'");
  INFO(info);
  CHECK(info.find("3 x 2") != std::string::npos);
  CHECK(info.find("4 channel") != std::string::npos);
  CHECK(info.find("float") != std::string::npos);
  CHECK(info.find("R, G, B, spp") != std::string::npos);
  CHECK(info.find("scenes/glass-ball.json") != std::string::npos);
  CHECK(info.find("tdpm/method") != std::string::npos);
  CHECK(info.find("zip") != std::string::npos);

  // Pixel values, row 0 first: "Pixel (x, y): R G B spp".
  const std::string dump = runCapture("oiiotool --dumpdata '" + path + "'");
  INFO(dump);
  std::istringstream lines(dump);
  std::string line;
  int seen = 0;
  while (std::getline(lines, line)) {
    int x, y;
    float v[4];
    if (std::sscanf(line.c_str(), " Pixel (%d, %d): %f %f %f %f", &x, &y, &v[0], &v[1], &v[2], &v[3]) != 6) continue;
    REQUIRE(f.color.inside(x, y));
    const Rgb& p = f.color.at(x, y);
    CHECK(v[0] == p.r);
    CHECK(v[1] == p.g);
    CHECK(v[2] == p.b);
    CHECK(v[3] == f.extra[0].values[size_t(y * 3 + x)]);
    ++seen;
  }
  CHECK(seen == 6);

  // And the other direction: a file OpenImageIO wrote, read by us.
  const std::string theirs = dir / "theirs.exr";
  REQUIRE(std::system(("oiiotool --pattern constant:color=0.5,0.25,2 5x4 3 -d float -o '" + theirs +
                       "' >/dev/null 2>&1")
                          .c_str()) == 0);
  ExrFile g = readExr(theirs);
  REQUIRE(g.color.width == 5);
  REQUIRE(g.color.height == 4);
  for (const Rgb& p : g.color.pixels) {
    CHECK(p.r == 0.5f);
    CHECK(p.g == 0.25f);
    CHECK(p.b == 2.0f);
  }
}

// ---- PNG preview ----

TEST_CASE("png: sRGB encoding of known values, clamping and exposure") {
  CHECK(toSrgb8(0.0f) == 0);
  CHECK(toSrgb8(-1.0f) == 0);
  CHECK(toSrgb8(std::numeric_limits<float>::quiet_NaN()) == 0);
  CHECK(toSrgb8(1.0f) == 255);
  CHECK(toSrgb8(7.5f) == 255);
  CHECK(toSrgb8(std::numeric_limits<float>::infinity()) == 255);
  CHECK(toSrgb8(0.5f) == 188);     // 1.055 * 0.5^(1/2.4) - 0.055 = 0.7354
  CHECK(toSrgb8(0.18f) == 118);    // middle grey: 0.4614
  CHECK(toSrgb8(0.001f) == 3);     // linear segment: 12.92 * 0.001 * 255 = 3.29
  CHECK(srgbEncode(0.0031308f) == doctest::Approx(0.04045f).epsilon(1e-3));
  // Monotone over the whole range.
  int prev = 0;
  for (int i = 0; i <= 1000; ++i) {
    int v = toSrgb8(float(i) / 1000.0f);
    CHECK(v >= prev);
    prev = v;
  }

  ImageRgb img(2, 1);
  img.at(0, 0) = Rgb(0.25f, 0.5f, 1.0f);
  img.at(1, 0) = Rgb(2.0f, 0.0f, 0.09f);
  ImageRgb8 plus1 = toPreview(img, 1.0f);  // x2
  CHECK(plus1.rgb == std::vector<uint8_t>{188, 255, 255, 255, 0, toSrgb8(0.18f)});
  ImageRgb8 minus1 = toPreview(img, -1.0f);  // x0.5
  CHECK(minus1.rgb[2] == 188);
  CHECK(minus1.rgb[3] == 255);
}

TEST_CASE("png: preview file round trip, atomic, and readable by others") {
  TempDir dir;
  ImageRgb img(5, 3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x) img.at(x, y) = Rgb(float(x) / 4.0f, float(y) / 2.0f, 0.5f);
  const std::string path = dir / "prev.png";
  writePngPreview(path, img, 0.0f);
  CHECK(dir.list().size() == 1);
  ImageRgb8 back = readPng(path);
  REQUIRE(back.width == 5);
  REQUIRE(back.height == 3);
  CHECK(back.rgb == toPreview(img, 0.0f).rgb);
  // Row 0 is the top row: pixel (4, 0) is (1, 0, 0.5).
  CHECK(back.rgb[3 * 4 + 0] == 255);
  CHECK(back.rgb[3 * 4 + 1] == 0);
  CHECK(back.rgb[3 * 4 + 2] == 188);

  checkError([&] { readPng(dir / "missing.png"); }, {dir / "missing.png"});
  writeBytes(dir / "text.png", "not a png");
  checkError([&] { readPng(dir / "text.png"); }, {dir / "text.png"});

  if (haveOiiotool()) {
    const std::string info = runCapture("oiiotool --info -v '" + path + "'");
    INFO(info);
    CHECK(info.find("5 x 3") != std::string::npos);
    CHECK(info.find("3 channel") != std::string::npos);
    CHECK(info.find("uint8") != std::string::npos);
    CHECK(info.find("sRGB") != std::string::npos);
  }
}

TEST_CASE("png: the preview path sits beside the output") {
  CHECK(previewPathFor("out.exr") == "out.png");
  CHECK(previewPathFor("renders/a.b.exr") == "renders/a.b.png");
  CHECK(previewPathFor("dir.v2/out") == "dir.v2/out.png");
  CHECK(previewPathFor("out") == "out.png");
  CHECK(previewPathFor(".hidden") == ".hidden.png");
  CHECK(previewPathFor("dir/.hidden") == "dir/.hidden.png");
  CHECK(previewPathFor("out.PNG") == "out.preview.png");
  CHECK(previewPathFor("x/out.png") == "x/out.preview.png");
}
