// tests/test_resume_damage.cpp — issue 27 items 3, 6 (--resume) and 7: a
// resume file whose progressive state was damaged or edited is refused
// before any work with "damaged progressive state: FILE: FIELD ...", a FIFO
// is refused at once instead of blocking, and a scene too bright for the
// float sums is refused where the sums overflow (exit 1, nothing written).
// The states are a real 2-pass render's, edited one field at a time.
#include <doctest/doctest.h>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <Imath/half.h>
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <utility>
#include <string>
#include <vector>

#include "cli_harness.h"
#include "image/exr.h"

using namespace tdpm;

namespace {

const std::string kScene = std::string(TDPM_SOURCE_DIR) + "/scenes/cube-caustic.json";
const std::string kArgs = " -m time --progressive --resolution 16x12 --spp 1 --photons 2000 --global-photons 500 -q ";

struct Fixture {
  std::string dir = test::makeTempDir();
  std::string good = dir + "/good.exr";
  Fixture() {
    test::CommandResult r = test::runTdpm("render '" + kScene + "'" + kArgs + "--passes 2 -o '" + good + "'");
    REQUIRE_MESSAGE(r.exitCode == 0, r.output);
  }
  ~Fixture() { std::system(("rm -rf '" + dir + "'").c_str()); }

  // Resumes `file` for one more pass; the output must not appear.
  test::CommandResult resume(const std::string& file) const {
    const std::string out = dir + "/out.exr";
    test::CommandResult r = test::runTdpm("render '" + kScene + "'" + kArgs + "--passes 3 --resume '" + file +
                                          "' -o '" + out + "'");
    CHECK(!test::fileExists(out));
    CHECK(!test::fileExists(dir + "/out.png"));
    return r;
  }
  // good.exr with attributes set (name -> text), as `name`.
  std::string edited(const std::string& name, const std::map<std::string, std::string>& set) const {
    image::ExrFile exr = image::readExr(good);
    for (const auto& kv : set) exr.metadata[kv.first] = kv.second;
    std::string path = dir + "/" + name;
    image::writeExr(path, exr);
    return path;
  }
  // good.exr with one value of a layer replaced.
  std::string editedLayer(const std::string& name, const std::string& layer, size_t pixel, float value) const {
    image::ExrFile exr = image::readExr(good);
    for (image::Channel& c : exr.extra)
      if (c.name == layer) c.values.at(pixel) = value;
    std::string path = dir + "/" + name;
    image::writeExr(path, exr);
    return path;
  }
  double scalar(const std::string& name) const {
    return std::stod(image::readExr(good).metadata.at("tdpm/progressive/scalar/" + name));
  }
};

// good.exr rewritten by OpenEXR itself, as another tool would convert it:
// the extra channels as `type`, the file with `compression`.
std::string convert(const Fixture& f, const std::string& name, Imf::PixelType type, Imf::Compression compression) {
  image::ExrFile exr = image::readExr(f.good);
  const int w = exr.color.width, h = exr.color.height;
  const size_t n = size_t(w) * size_t(h);
  Imf::Header header(w, h);
  header.compression() = compression;
  for (const auto& kv : exr.metadata) header.insert(kv.first, Imf::StringAttribute(kv.second));
  Imf::FrameBuffer fb;
  std::vector<float> rgb[3];
  const char* names[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    rgb[c].resize(n);
    for (size_t i = 0; i < n; ++i) rgb[c][i] = exr.color.pixels[i][c];
    header.channels().insert(names[c], Imf::Channel(Imf::FLOAT));
    fb.insert(names[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(rgb[c].data()), sizeof(float), sizeof(float) * w));
  }
  std::vector<std::vector<half>> halves(exr.extra.size());
  for (size_t k = 0; k < exr.extra.size(); ++k) {
    const image::Channel& c = exr.extra[k];
    header.channels().insert(c.name, Imf::Channel(type));
    char* base;
    size_t size;
    if (type == Imf::HALF) {
      halves[k].assign(c.values.begin(), c.values.end());
      base = reinterpret_cast<char*>(halves[k].data());
      size = sizeof(half);
    } else {
      base = reinterpret_cast<char*>(const_cast<float*>(c.values.data()));
      size = sizeof(float);
    }
    fb.insert(c.name, Imf::Slice(type, base, size, size * size_t(w)));
  }
  std::string path = f.dir + "/" + name;
  {
    Imf::OutputFile out(path.c_str(), header);
    out.setFrameBuffer(fb);
    out.writePixels(h);
  }
  return path;
}

void refused(const test::CommandResult& r, const std::string& file, const std::string& what) {
  INFO(r.output);
  CHECK(r.exitCode == 1);
  CHECK(r.output.find("tdpm: error: damaged progressive state: " + file + ": " + what) != std::string::npos);
}

}  // namespace

TEST_CASE("resume damage: the written state resumes; each damaged field is refused by name before any work") {
  Fixture f;
  {  // The control: the file as written resumes (and the output appears).
    test::CommandResult r = test::runTdpm("render '" + kScene + "'" + kArgs + "--passes 3 --resume '" + f.good +
                                          "' -o '" + f.dir + "/ok.exr'");
    INFO(r.output);
    CHECK(r.exitCode == 0);
    CHECK(test::fileExists(f.dir + "/ok.exr"));
  }
  const std::string paths = "tdpm/progressive/scalar/photons.caustic_paths_per_pass";
  // 1e18 grew 7 GB, -5 was an internal error, a fraction a failed assertion.
  for (const char* v : {"1e18", "-5", "1000.5"}) {
    CAPTURE(v);
    std::string p = f.edited("paths.exr", {{paths, v}});
    refused(f.resume(p), p, paths + " is ");
  }
  // 0 rendered without caustics, exit 0: the photons emitted disagree.
  std::string p = f.edited("zero.exr", {{paths, "0"}});
  refused(f.resume(p), p, "tdpm/progressive/scalar/photons.emitted is ");
  // 2^31 - 1 passes overflowed (pass 18446744071562067968, radius -nan).
  p = f.edited("passes.exr", {{"tdpm/progressive/passes", "2147483647"}});
  refused(f.resume(p), p, "tdpm/progressive/passes is 2147483647, outside [1, 16777216]");
  p = f.edited("passes0.exr", {{"tdpm/progressive/passes", "0"}});
  refused(f.resume(p), p, "tdpm/progressive/passes is 0, outside [1, 16777216]");
  // 2^24 - 1 passes with matching photon counts divided the image by 2^24:
  // the spp layer says 2 passes.
  const double perPass = f.scalar("photons.caustic_paths_per_pass") + f.scalar("photons.global_paths_per_pass");
  char emitted[64];
  std::snprintf(emitted, sizeof emitted, "%.17g", 16777215.0 * perPass);
  p = f.edited("many.exr", {{"tdpm/progressive/passes", "16777215"}, {"tdpm/progressive/scalar/photons.emitted", emitted}});
  refused(f.resume(p), p, "layer progressive.spp is ");
  // Kernels and sums must be finite; an unknown scalar is not the render's.
  p = f.edited("radius.exr", {{"tdpm/progressive/scalar/kernel.caustic.radius_1", "nan"}});
  refused(f.resume(p), p, "tdpm/progressive/scalar/kernel.caustic.radius_1 is nan, not finite");
  p = f.edited("unknown.exr", {{"tdpm/progressive/scalar/bonus", "1"}});
  refused(f.resume(p), p, "tdpm/progressive/scalar/bonus is not a value a progressive render writes");
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  p = f.editedLayer("spp-nan.exr", "progressive.spp", 17, nan);
  refused(f.resume(p), p, "layer progressive.spp is nan at pixel (1, 1), not finite");
  p = f.editedLayer("sum-inf.exr", "progressive.sum.G", 0, inf);
  refused(f.resume(p), p, "layer progressive.sum.G is inf at pixel (0, 0), not finite");
  p = f.editedLayer("sumsq-neg.exr", "progressive.sumsq.B", 3, -1.0f);
  refused(f.resume(p), p, "layer progressive.sumsq.B is -1 at pixel (3, 0), a negative sum of squares");
}

TEST_CASE("resume damage: a state converted to HALF or to a lossy compression is refused; lossless ones resume") {
  Fixture f;
  std::string p = convert(f, "half.exr", Imf::HALF, Imf::ZIP_COMPRESSION);
  refused(f.resume(p), p, "layer progressive.");
  CHECK(f.resume(p).output.find("is stored as HALF, not FLOAT") != std::string::npos);
  for (auto [c, name] : {std::pair{Imf::DWAA_COMPRESSION, "dwaa"}, std::pair{Imf::DWAB_COMPRESSION, "dwab"},
                         std::pair{Imf::B44_COMPRESSION, "b44"}, std::pair{Imf::PXR24_COMPRESSION, "pxr24"}}) {
    CAPTURE(name);
    p = convert(f, std::string(name) + ".exr", Imf::FLOAT, c);
    refused(f.resume(p), p, std::string("the file is ") + name + "-compressed, which is lossy");
  }
  // The check is about what the floats went through, not about who wrote the file.
  p = convert(f, "piz.exr", Imf::FLOAT, Imf::PIZ_COMPRESSION);
  test::CommandResult r = test::runTdpm("render '" + kScene + "'" + kArgs + "--passes 3 --resume '" + p + "' -o '" +
                                        f.dir + "/piz-out.exr'");
  INFO(r.output);
  CHECK(r.exitCode == 0);
}

TEST_CASE("resume damage: a FIFO given to --resume is refused at once (it blocked for ever)") {
  Fixture f;
  const std::string fifo = f.dir + "/pipe.exr";
  REQUIRE(::mkfifo(fifo.c_str(), 0644) == 0);
  // No writer ever opens it: a blocking open() would hang this test.
  test::CommandResult r = f.resume(fifo);
  INFO(r.output);
  CHECK(r.exitCode == 1);
  CHECK(r.output.find("tdpm: error: --resume " + fifo +
                      ": is a FIFO (named pipe), not an OpenEXR file: only regular files are read") != std::string::npos);
}

TEST_CASE("resume damage: a scene too bright for the float sums is refused where they overflow, not written as +Inf") {
  // A 1e30 W lamp: the pass values (~1e26) square beyond FLT_MAX. Before, the
  // sumsq layers held +Inf, the variance 3.4e38, exit 0, and resume took it.
  Fixture f;
  std::string text;
  {
    std::ifstream in(kScene);
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  const std::string from = "\"power\": [160, 152, 140]";
  REQUIRE(text.find(from) != std::string::npos);
  text.replace(text.find(from), from.size(), "\"power\": [1e30, 1e30, 1e30]");
  const std::string bright = f.dir + "/bright.json", out = f.dir + "/bright.exr";
  test::writeFile(bright, text);
  test::CommandResult r = test::runTdpm("render '" + bright + "'" + kArgs + "--passes 2 -o '" + out + "'");
  INFO(r.output);
  CHECK(r.exitCode == 1);
  CHECK(r.output.find("tdpm: error: progressive pass 1: pixel (") != std::string::npos);
  CHECK(r.output.find("is beyond the largest float") != std::string::npos);
  CHECK(!test::fileExists(out));
  // The same scene at 1e10 W (values ~1e6, squares ~1e12) renders, finite.
  text.replace(text.find("[1e30, 1e30, 1e30]"), 18, "[1e10, 1e10, 1e10]");
  test::writeFile(bright, text);
  r = test::runTdpm("render '" + bright + "'" + kArgs + "--passes 2 -o '" + out + "'");
  REQUIRE_MESSAGE(r.exitCode == 0, r.output);
  image::ExrFile exr = image::readExr(out);
  const image::Channel* sq = exr.findChannel("progressive.sumsq.R");
  REQUIRE(sq);
  float top = 0;
  for (float v : sq->values) {
    CHECK(std::isfinite(v));
    top = std::max(top, v);
  }
  CHECK(top > 1e6f);  // the test sees bright values, not a black image
}
