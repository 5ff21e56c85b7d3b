// tests/test_progressive_io.cpp — render/progressive_io: a ProgressiveState
// written into an EXR file and read back is the same state, bit for bit;
// files without a state or with a damaged one are told apart.
#include <doctest/doctest.h>

#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>

#include "cli_harness.h"
#include "core/error.h"
#include "image/exr.h"
#include "render/progressive_io.h"

using namespace tdpm;

namespace {

uint64_t bitsOf(double v) {
  uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

float floatFromBits(uint32_t b) {
  float f;
  std::memcpy(&f, &b, sizeof f);
  return f;
}

// An image of w x h with the state's layers beside it, as the render writes it.
image::ExrFile exrWith(const ProgressiveState& s, int w, int h) {
  image::ExrFile exr;
  exr.color = image::ImageRgb(w, h);
  for (size_t i = 0; i < exr.color.pixels.size(); ++i) exr.color.pixels[i] = Rgb(float(i), 0.5f, 0.25f);
  exr.extra.push_back(image::Channel{"spp", std::vector<float>(size_t(w) * size_t(h), 16.0f)});
  exr.metadata["tdpm/method"] = "time";
  addProgressiveState(s, exr);
  return exr;
}

// Doubles that "%.6g" or a float would not keep.
const double kAwkward[] = {0.1,
                           1.0 / 3.0,
                           std::nextafter(1.0, 2.0),
                           9007199254740993.0,  // 2^53 + 1 (rounds to 2^53: still must survive as stored)
                           std::numeric_limits<double>::denorm_min(),
                           2.2250738585072014e-308,  // DBL_MIN
                           1e-310,
                           DBL_MAX,
                           -0.0,
                           -123456.78901234567,
                           6.02214076e23,
                           std::numeric_limits<double>::infinity(),
                           -std::numeric_limits<double>::infinity()};

ProgressiveState sampleState(int w, int h) {
  ProgressiveState s;
  s.fingerprint = "3f2a9c0d11e4b785";
  s.passesDone = 37;
  s.settings = {{"method", "time"}, {"photons", "100000"}, {"alpha", "0.7"}, {"resolution", "5x3"},
                {"note", "spaces, commas = and / are fine"}};
  // Every scalar of the table an awkward double (the state is ours: its
  // fields may be written through the table's pointers).
  s.pilot.done = true;
  size_t i = 0;
  const size_t awkward = sizeof kAwkward / sizeof kAwkward[0];
  for (const ProgressiveScalar& sc : progressiveScalars(s)) *const_cast<double*>(sc.value) = kAwkward[i++ % awkward];
  s.totals.photonsEmitted = 123456789012.0;
  s.totals.kernelHalfWindow = std::numeric_limits<double>::quiet_NaN();
  const size_t n = size_t(w) * size_t(h);
  // Floats that a conversion would change: NaN with a payload, -0, the
  // smallest subnormal, FLT_MAX, infinity, and plain values.
  const float special[] = {floatFromBits(0x7fc01234u), -0.0f, floatFromBits(1u), FLT_MAX,
                           std::numeric_limits<float>::infinity(), 0.1f, -3.5f};
  for (const char* name : {"sum.R", "sum.G", "sum.B", "spp", "radius"}) {
    std::vector<float> v(n);
    for (size_t i = 0; i < n; ++i) v[i] = i < 7 ? special[i] : float(i) * 0.37f + float(name[0]);
    s.layers[name] = v;
  }
  return s;
}

}  // namespace

TEST_CASE("progressive io: exact double text") {
  for (double v : kAwkward) {
    CAPTURE(v);
    double back = 12345;
    REQUIRE(parseExactDouble(exactDoubleText(v), back));
    CHECK(bitsOf(back) == bitsOf(v));
  }
  double nan = 0;
  REQUIRE(parseExactDouble(exactDoubleText(std::nan("")), nan));
  CHECK(std::isnan(nan));
  double x = 0;
  CHECK(!parseExactDouble("", x));
  CHECK(!parseExactDouble("1.5x", x));
  CHECK(!parseExactDouble(" 1.5", x));
  CHECK(!parseExactDouble("1e999", x));  // overflow is not infinity written as "inf"
}

TEST_CASE("progressive io: a state survives an EXR file bit for bit") {
  const std::string dir = test::makeTempDir();
  const std::string path = dir + "/state.exr";
  const int w = 5, h = 3;
  const ProgressiveState s = sampleState(w, h);
  image::writeExr(path, exrWith(s, w, h));

  const image::ExrFile back = image::readExr(path);
  // The image itself and the other layers are untouched.
  CHECK(back.color.pixels[4].r == 4.0f);
  REQUIRE(back.findChannel("spp"));
  CHECK(back.findChannel("spp")->values[0] == 16.0f);
  CHECK(back.metadata.at("tdpm/method") == "time");
  CHECK(back.findChannel("progressive.sum.R"));

  std::optional<ProgressiveState> r = progressiveStateOf(back, path);
  REQUIRE(r);
  CHECK(r->fingerprint == s.fingerprint);
  CHECK(r->passesDone == 37);
  CHECK(r->settings == s.settings);
  CHECK(r->pilot.done);
  const std::vector<ProgressiveScalar> want = progressiveScalars(s), got = progressiveScalars(*r);
  REQUIRE(got.size() == want.size());
  for (size_t j = 0; j < want.size(); ++j) {
    CAPTURE(want[j].name);
    CHECK(back.metadata.count("tdpm/progressive/scalar/" + want[j].name));
    if (std::isnan(*want[j].value)) CHECK(std::isnan(*got[j].value));
    else CHECK(bitsOf(*got[j].value) == bitsOf(*want[j].value));
  }
  REQUIRE(r->layers.size() == s.layers.size());
  for (const auto& [name, v] : s.layers) {
    CAPTURE(name);
    REQUIRE(r->layers.count(name));
    REQUIRE(r->layers.at(name).size() == v.size());
    CHECK(std::memcmp(r->layers.at(name).data(), v.data(), v.size() * sizeof(float)) == 0);
  }
  std::system(("rm -rf '" + dir + "'").c_str());
}

TEST_CASE("progressive io: adding a state replaces the old one") {
  ProgressiveState a = sampleState(2, 2);
  image::ExrFile exr = exrWith(a, 2, 2);
  ProgressiveState b;
  b.fingerprint = "other";
  b.passesDone = 1;
  b.layers["sum.R"] = std::vector<float>(4, 1.0f);
  addProgressiveState(b, exr);
  std::optional<ProgressiveState> r = progressiveStateOf(exr, "x.exr");
  REQUIRE(r);
  CHECK(r->passesDone == 1);
  CHECK(r->settings.empty());
  CHECK(!r->pilot.done);
  for (const auto& kv : exr.metadata) CHECK(kv.first.rfind("tdpm/progressive/scalar/", 0) != 0);
  CHECK(r->layers.size() == 1);
  CHECK(!exr.findChannel("progressive.radius"));
  CHECK(exr.findChannel("spp"));  // not the state's: kept
}

TEST_CASE("progressive io: no state, and damaged states") {
  image::ExrFile plain;
  plain.color = image::ImageRgb(2, 2);
  plain.metadata["tdpm/method"] = "time";
  CHECK(!progressiveStateOf(plain, "plain.exr"));

  const ProgressiveState s = sampleState(2, 2);
  auto expectError = [&](auto edit, const std::string& words) {
    image::ExrFile exr = exrWith(s, 2, 2);
    edit(exr);
    std::string msg;
    try {
      progressiveStateOf(exr, "old.exr");
    } catch (const Error& e) {
      msg = e.what();
    }
    CAPTURE(msg);
    // Another layout version is "old.exr: ..."; a damaged state says so first.
    CHECK((msg.rfind("old.exr: ", 0) == 0 || msg.rfind("damaged progressive state: old.exr: ", 0) == 0));
    CHECK(msg.find(words) != std::string::npos);
  };
  expectError([](image::ExrFile& e) { e.metadata["tdpm/progressive/version"] = "2"; }, "layout version '2'");
  expectError([](image::ExrFile& e) { e.metadata["tdpm/progressive/passes"] = "-1"; },
              "tdpm/progressive/passes is '-1'");
  expectError([](image::ExrFile& e) { e.metadata["tdpm/progressive/passes"] = "3 passes"; }, "not a number of passes");
  expectError([](image::ExrFile& e) { e.metadata.erase("tdpm/progressive/fingerprint"); },
              "attribute tdpm/progressive/fingerprint is missing");
  expectError([](image::ExrFile& e) { e.metadata["tdpm/progressive/scalar/seconds"] = "12,5"; },
              "tdpm/progressive/scalar/seconds is '12,5', not a number");
  expectError([](image::ExrFile& e) { e.metadata.erase("tdpm/progressive/scalar/kernel.global.half_window_1"); },
              "tdpm/progressive/scalar/kernel.global.half_window_1 is missing");
  expectError([](image::ExrFile& e) { e.metadata["tdpm/progressive/scalar/kernel.volume.radius_1"] = "1"; },
              "tdpm/progressive/scalar/kernel.volume.radius_1 is not a value a progressive render writes");
  expectError(
      [](image::ExrFile& e) {
        for (auto it = e.extra.begin(); it != e.extra.end(); ++it)
          if (it->name == "progressive.sum.G") {
            e.extra.erase(it);
            break;
          }
      },
      "layer progressive.sum.G is missing");
  expectError([](image::ExrFile& e) { e.extra.push_back(image::Channel{"progressive.extra", std::vector<float>(4)}); },
              "layer progressive.extra is not listed");
}

TEST_CASE("progressive io: adding a moved state gives the same file content") {
  const ProgressiveState s = sampleState(3, 2);
  const image::ExrFile copied = exrWith(s, 3, 2);
  ProgressiveState moved = s;
  image::ExrFile exr;
  exr.color = image::ImageRgb(3, 2);
  addProgressiveState(std::move(moved), exr);
  CHECK(moved.layers.empty());
  CHECK(exr.metadata.at("tdpm/progressive/layers") == "radius,spp,sum.B,sum.G,sum.R");
  std::optional<ProgressiveState> a = progressiveStateOf(copied, "a.exr"), b = progressiveStateOf(exr, "b.exr");
  REQUIRE(a);
  REQUIRE(b);
  CHECK(a->passesDone == b->passesDone);
  CHECK(a->settings == b->settings);
  for (const auto& [name, v] : a->layers)
    CHECK(std::memcmp(b->layers.at(name).data(), v.data(), v.size() * sizeof(float)) == 0);
}
